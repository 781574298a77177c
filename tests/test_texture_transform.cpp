// KHR_texture_transform against a known answer: a glTF written here (a screen-filling
// quad, an orthographic camera, a 4 x 4 texture of distinct colours sampled NEAREST
// with REPEAT), rendered by the kit's stage 1 (the solutions' geometry pass), and the
// albedo at the centre of each of 8 x 8 screen cells matched to the texel it shows.
// The expected texel of every cell is a table written by hand below, from the
// convention the Khronos sample models (TextureTransformTest, TextureTransformMultiTest),
// the Khronos sample viewer, three.js and Babylon share; not from the loader's matrix
// nor from any formula the kit's code runs.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <sstream>
#include <string>

#include "kit_test.h"
#include "kit_test_files.h"
#include "images/texture_prepare.h"

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

// The render: 8 x 8 cells of 9 x 9 pixels, so each cell has a centre pixel. The
// orthographic camera (xmag = ymag = 1) sees exactly the quad [-1, 1]^2, so the
// centre of pixel (x, y) (row 0 at the top) is at u0 = (x + 0.5) / 72, v0 = (y + 0.5) / 72
// on TEXCOORD_0, and the centre pixel of cell (i, j) at u0 = (i + 0.5) / 8, v0 = (j + 0.5) / 8.
constexpr int kCells = 8, kCellPixels = 9, kSize = kCells * kCellPixels;
constexpr int kTexels = 4;  // the texture is kTexels x kTexels

// Texel (column c, row r; row 0 is the image's top row, where glTF's v = 0 is) has the
// sRGB code (85 c, 85 r, 255): 16 colours at least 0.09 apart once decoded, none of
// them the background's. Its index in the tables below is 4 r + c.
std::array<unsigned char, 3> texel_code(int column, int row) {
  return {static_cast<unsigned char>(85 * column), static_cast<unsigned char>(85 * row), 255};
}

// The transform both cases use: rotation pi/2, offset (0.25, 0.5), scale (2, 1).
constexpr double kRotation = 1.5707963267948966;
constexpr double kOffset[2] = {0.25, 0.5};
constexpr double kScale[2] = {2.0, 1.0};

// glTF's UV space has v growing down the image. In it the Khronos convention is
//   u' = ox + cos(r) sx u + sin(r) sy v,   v' = oy - sin(r) sx u + cos(r) sy v
// (the extension README's GLSL listing turns the other way: glTF issue #1563). At
// r = pi/2 (cos 0, sin 1) with the offset and scale above:
//   u' = 0.25 + v,   v' = 0.5 - 2 u,
// so the texel column is floor(4 u') = floor(1 + 4 v) and the row floor(4 v') =
// floor(2 - 8 u), both modulo 4 (REPEAT). Column j of the screen walks down the
// texture's columns, and each screen cell to the right goes one texel row up.
//
// TEXCOORD_0 (u = u0, v = v0). Worked cell (i = 2, j = 4): u = 2.5/8 = 0.3125,
// v = 4.5/8 = 0.5625; u' = 0.25 + 0.5625 = 0.8125, 4 u' = 3.25: column 3;
// v' = 0.5 - 0.625 = -0.125, 4 v' = -0.5, floor -1 = row 3 modulo 4; texel 4*3 + 3 = 15.
// Down the screen (j = 0..7) the columns are 1 1 2 2 3 3 0 0 (4 v = 0.25, 0.75, ...),
// across it (i = 0..7) the rows 1 0 3 2 1 0 3 2 (4 v' = 1.5, 0.5, -0.5, ...): each
// sample at a quarter or half texel from the nearest texel edge.
// (The README listing's direction, u' = 0.25 - v, v' = 0.5 + 2 u, shows texel 2 in
// that cell, and a different texel in every cell of the table.)
constexpr int kExpectedTexcoord0[kCells][kCells] = {
    {5, 1, 13, 9, 5, 1, 13, 9},   {5, 1, 13, 9, 5, 1, 13, 9},   {6, 2, 14, 10, 6, 2, 14, 10},
    {6, 2, 14, 10, 6, 2, 14, 10}, {7, 3, 15, 11, 7, 3, 15, 11}, {7, 3, 15, 11, 7, 3, 15, 11},
    {4, 0, 12, 8, 4, 0, 12, 8},   {4, 0, 12, 8, 4, 0, 12, 8}};

// TEXCOORD_1 is TEXCOORD_0 mirrored left to right: u = 1 - u0, v = v0, read through the
// extension's texCoord (1) over the texture reference's (0). Then v' = 0.5 - 2 (1 - u0)
// = -1.5 + 2 u0, and across the screen the rows are 2 3 0 1 2 3 0 1; the columns are
// as above. Worked cell (i = 2, j = 4): u = 0.6875, v = 0.5625; u' = 0.8125: column 3;
// v' = 0.5 - 1.375 = -0.875, 4 v' = -3.5, floor -4 = row 0 modulo 4; texel 3.
constexpr int kExpectedTexcoord1[kCells][kCells] = {
    {9, 13, 1, 5, 9, 13, 1, 5},   {9, 13, 1, 5, 9, 13, 1, 5},   {10, 14, 2, 6, 10, 14, 2, 6},
    {10, 14, 2, 6, 10, 14, 2, 6}, {11, 15, 3, 7, 11, 15, 3, 7}, {11, 15, 3, 7, 11, 15, 3, 7},
    {8, 12, 0, 4, 8, 12, 0, 4},   {8, 12, 0, 4, 8, 12, 0, 4}};

std::string bytes_of(const void* data, size_t size) { return std::string(static_cast<const char*>(data), size); }

// Writes the scene into a fresh folder: quad.gltf, quad.bin and texels.png. The
// material's base colour texture carries the transform; `texcoord_override` adds
// the extension's texCoord (the texture reference itself names TEXCOORD_0).
fs::path write_quad_scene(const std::string& name, int texcoord_override) {
  const fs::path dir = kit::test::temp_dir("texture_transform/" + name);
  // Corners BL, BR, TR, TL of the quad in the z = 0 plane, facing +z.
  const float positions[4][3] = {{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}};
  const float normals[4][3] = {{0, 0, 1}, {0, 0, 1}, {0, 0, 1}, {0, 0, 1}};
  const float uv0[4][2] = {{0, 1}, {1, 1}, {1, 0}, {0, 0}};  // glTF: v = 0 at the top edge
  const float uv1[4][2] = {{1, 1}, {0, 1}, {0, 0}, {1, 0}};  // uv0 mirrored: 1 - u0, v0
  const uint16_t indices[6] = {0, 1, 2, 0, 2, 3};            // CCW seen from +z
  const std::string parts[] = {bytes_of(positions, sizeof positions), bytes_of(normals, sizeof normals),
                               bytes_of(uv0, sizeof uv0), bytes_of(uv1, sizeof uv1), bytes_of(indices, sizeof indices)};
  std::string bin;
  json views = json::array();
  for (const std::string& part : parts) {
    views.push_back({{"buffer", 0}, {"byteOffset", bin.size()}, {"byteLength", part.size()}});
    bin += part;
  }
  json accessors = json::array({
      {{"bufferView", 0}, {"componentType", 5126}, {"count", 4}, {"type", "VEC3"}, {"min", {-1, -1, 0}}, {"max", {1, 1, 0}}},
      {{"bufferView", 1}, {"componentType", 5126}, {"count", 4}, {"type", "VEC3"}},
      {{"bufferView", 2}, {"componentType", 5126}, {"count", 4}, {"type", "VEC2"}},
      {{"bufferView", 3}, {"componentType", 5126}, {"count", 4}, {"type", "VEC2"}},
      {{"bufferView", 4}, {"componentType", 5123}, {"count", 6}, {"type", "SCALAR"}},
  });
  json transform = {{"offset", {kOffset[0], kOffset[1]}}, {"rotation", kRotation}, {"scale", {kScale[0], kScale[1]}}};
  if (texcoord_override >= 0) transform["texCoord"] = texcoord_override;
  const json doc = {
      {"asset", {{"version", "2.0"}}},
      {"extensionsUsed", {"KHR_texture_transform"}},
      {"scene", 0},
      {"scenes", {{{"nodes", {0, 1}}}}},
      {"nodes", {{{"mesh", 0}}, {{"camera", 0}, {"translation", {0, 0, 2}}}}},  // the camera looks along -z
      {"cameras", {{{"type", "orthographic"}, {"orthographic", {{"xmag", 1}, {"ymag", 1}, {"znear", 0.5}, {"zfar", 4}}}}}},
      {"meshes",
       {{{"primitives",
          {{{"attributes", {{"POSITION", 0}, {"NORMAL", 1}, {"TEXCOORD_0", 2}, {"TEXCOORD_1", 3}}},
            {"indices", 4},
            {"material", 0}}}}}}},
      {"materials",
       {{{"pbrMetallicRoughness",
          {{"baseColorTexture", {{"index", 0}, {"extensions", {{"KHR_texture_transform", transform}}}}},
           {"metallicFactor", 0.0}}}}}},
      {"textures", {{{"source", 0}, {"sampler", 0}}}},
      {"samplers", {{{"magFilter", 9728}, {"minFilter", 9728}, {"wrapS", 10497}, {"wrapT", 10497}}}},  // NEAREST, REPEAT
      {"images", {{{"uri", "texels.png"}}}},
      {"buffers", {{{"uri", "quad.bin"}, {"byteLength", bin.size()}}}},
      {"bufferViews", views},
      {"accessors", accessors},
  };
  kit::test::write_file(dir / "quad.bin", bin);
  kit::test::write_file(dir / "quad.gltf", doc.dump(2));
  kit::Image texels(kTexels, kTexels, 3);
  for (int row = 0; row < kTexels; ++row)
    for (int column = 0; column < kTexels; ++column)
      for (int c = 0; c < 3; ++c) texels.at(column, row, c) = texel_code(column, row)[c] / 255.0f;
  kit::write_image((dir / "texels.png").string(), texels);
  return dir / "quad.gltf";
}

// The texel index (4 r + c) whose decoded colour the albedo at pixel (x, y) is, or -1
// when no texel's is within 0.02 (a quarter of the smallest gap between two texels).
int texel_at(const kit::Image& albedo, int x, int y) {
  for (int row = 0; row < kTexels; ++row)
    for (int column = 0; column < kTexels; ++column) {
      double worst = 0.0;
      for (int c = 0; c < 3; ++c)
        worst = std::max(worst, std::fabs(albedo.at(x, y, c) - kit::srgb_to_linear(texel_code(column, row)[c] / 255.0)));
      if (worst < 0.02) return kTexels * row + column;
    }
  return -1;
}

std::string grid_text(const int (&grid)[kCells][kCells]) {
  std::ostringstream out;
  for (const auto& line : grid) {
    for (int i = 0; i < kCells; ++i) out << (i ? " " : "") << (line[i] < 10 && line[i] >= 0 ? " " : "") << line[i];
    out << "\n";
  }
  return out.str();
}

// Renders the scene and compares the texel of every cell with `expected`; the whole
// grid is shown on failure.
void expect_texel_grid(const fs::path& gltf, const int (&expected)[kCells][kCells]) {
  ASSERT_TRUE(kit::test::scene(gltf.string()).warnings.empty()) << kit::test::scene(gltf.string()).warnings.front();
  kit::RenderSettings settings;
  settings.width = settings.height = kSize;
  const std::unique_ptr<kit::Renderer> renderer = kit::test::render_stage("gbuffer", gltf.string(), settings);
  const kit::Image albedo = renderer->read_view(kit::View::Albedo, true);
  ASSERT_EQ(albedo.width, kSize);
  ASSERT_EQ(albedo.height, kSize);
  int seen[kCells][kCells];
  size_t wrong = 0;
  for (int j = 0; j < kCells; ++j)
    for (int i = 0; i < kCells; ++i) {
      seen[j][i] = texel_at(albedo, kCellPixels * i + kCellPixels / 2, kCellPixels * j + kCellPixels / 2);
      wrong += seen[j][i] != expected[j][i];
    }
  EXPECT_EQ(wrong, 0u) << "texel index per screen cell (row j top to bottom, column i left to right)\nexpected:\n"
                       << grid_text(expected) << "rendered:\n"
                       << grid_text(seen);
}

// The texture reads TEXCOORD_0: rotation pi/2, offset and anisotropic scale.
TEST(TextureTransform, KhronosRotationOnTexcoord0MatchesTheHandTable) {
  expect_texel_grid(write_quad_scene("texcoord_0", -1), kExpectedTexcoord0);
}

// The same transform reading TEXCOORD_1 through the extension's texCoord override.
TEST(TextureTransform, KhronosRotationOnTexcoord1MatchesTheHandTable) {
  expect_texel_grid(write_quad_scene("texcoord_1", 1), kExpectedTexcoord1);
}

}  // namespace
