// kit-scenes: writes the kit's own glTF 2.0 test scenes.
//
//   kit-scenes OUT_DIR   ->  OUT_DIR/<name>/<name>.gltf + <name>.bin + *.png
//
// Everything is procedural and deterministic (no clocks, no random engines, only
// ordered containers), so the files are byte-identical on every run.
//
// Conventions the renderer relies on:
//  * right-handed, +Y up, metres; indexed (UNSIGNED_INT) triangle lists, CCW front faces;
//  * TEXCOORD_0 follows glTF: v = 0 is the top row of the image;
//  * TANGENT.w is chosen so that cross(N, T.xyz) * w points "up" in the image (towards
//    decreasing glTF v), which is where the normal map's +Y (green) points (OpenGL
//    convention, as glTF requires). A plainly mapped surface therefore has w = +1 and a
//    surface whose U runs backwards (mirrored) has w = -1.
#include <tiny_gltf.h>

#include <OpenImageIO/imageio.h>
#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>
#include <glm/gtc/type_precision.hpp>  // u8vec4
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <stdexcept>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

namespace fs = std::filesystem;

namespace {

// --- Brick texture parameters (shared by the colour map and the normal map) ---
constexpr int kTextureSize = 256;       // square; the pattern tiles seamlessly
constexpr int kBrickWidthPx = 64;       // divides kTextureSize; even, for the half-brick offset
constexpr int kBrickHeightPx = 32;      // divides kTextureSize into an even number of rows
constexpr float kMortarWidthPx = 6.0f;  // full width of a mortar joint
constexpr float kBevelPx = 3.0f;        // rounded brick edge between mortar and brick face
constexpr float kBumpDepthPx = 2.5f;    // height of a brick face above the mortar, in texels

constexpr int kCheckerCells = 4;  // checker cells per texture side

constexpr double kPi = 3.14159265358979323846;
constexpr double kZNear = 0.1;
constexpr double kZFar = 50.0;

// ---------------------------------------------------------------------------
// Images

struct Image8 {
  int width = 0;
  int height = 0;
  int channels = 0;
  std::vector<std::uint8_t> pixels;  // row 0 is the top of the image

  Image8(int w, int h, int c) : width(w), height(h), channels(c), pixels(size_t(w) * h * c, 0) {}

  void set(int x, int y, glm::vec3 rgb01) {
    std::uint8_t* p = &pixels[(size_t(y) * width + x) * channels];
    for (int i = 0; i < 3; ++i)
      p[i] = std::uint8_t(std::lround(std::clamp(rgb01[i], 0.0f, 1.0f) * 255.0f));
  }
};

// Integer hash (lowbias32) for per-brick colour variation: exact on every platform,
// unlike the standard library's random distributions.
std::uint32_t hash32(std::uint32_t x) {
  x ^= x >> 16;
  x *= 0x7feb352dU;
  x ^= x >> 15;
  x *= 0x846ca68bU;
  x ^= x >> 16;
  return x;
}

float hash01(std::uint32_t x) { return float(hash32(x) & 0xffffU) / 65535.0f; }

float smoothstep(float e0, float e1, float x) {
  const float t = std::clamp((x - e0) / (e1 - e0), 0.0f, 1.0f);
  return t * t * (3.0f - 2.0f * t);
}

struct BrickSample {
  float height;  // 0 in the mortar, 1 on a brick face, smooth bevel in between
  std::uint32_t brick_id;
};

// Where texel (x, y) falls in a running-bond brick pattern.
BrickSample sample_bricks(int x, int y) {
  // Wrap so that the normal map's central differences tile seamlessly too.
  x = (x % kTextureSize + kTextureSize) % kTextureSize;
  y = (y % kTextureSize + kTextureSize) % kTextureSize;
  const int row = y / kBrickHeightPx;
  const int shift = (row % 2) * (kBrickWidthPx / 2);  // odd rows offset by half a brick
  const int column = ((x + shift) / kBrickWidthPx) % (kTextureSize / kBrickWidthPx);
  const float lx = float((x + shift) % kBrickWidthPx) + 0.5f;  // texel centre inside the brick
  const float ly = float(y % kBrickHeightPx) + 0.5f;
  // Joints run along the cell borders; the distance to the nearest one gives the height.
  const float d = std::min(std::min(lx, kBrickWidthPx - lx), std::min(ly, kBrickHeightPx - ly));
  const float half_mortar = 0.5f * kMortarWidthPx;
  return {smoothstep(half_mortar, half_mortar + kBevelPx, d), std::uint32_t(row * 64 + column)};
}

Image8 make_brick_color() {
  Image8 img(kTextureSize, kTextureSize, 3);
  const glm::vec3 mortar(0.70f, 0.68f, 0.64f);  // sRGB-encoded: baseColor textures are sRGB
  const glm::vec3 brick(0.58f, 0.27f, 0.20f);
  for (int y = 0; y < img.height; ++y) {
    for (int x = 0; x < img.width; ++x) {
      const BrickSample s = sample_bricks(x, y);
      const float shade = 0.82f + 0.30f * hash01(s.brick_id);
      const glm::vec3 tint = brick * shade + glm::vec3(0.04f * hash01(s.brick_id + 977u), 0, 0);
      img.set(x, y, glm::mix(mortar, tint, s.height));
    }
  }
  return img;
}

// Tangent-space normal map stored as (n + 1) / 2 in linear 8-bit RGB:
// +X = +u (image right), +Y = image up (decreasing glTF v), +Z = out of the surface.
Image8 make_brick_normal() {
  Image8 img(kTextureSize, kTextureSize, 3);
  for (int y = 0; y < img.height; ++y) {
    for (int x = 0; x < img.width; ++x) {
      const float dh_dx = 0.5f * (sample_bricks(x + 1, y).height - sample_bricks(x - 1, y).height);
      // Rows grow downwards, so the slope towards "up" is minus the slope along the rows.
      const float dh_dup =
          -0.5f * (sample_bricks(x, y + 1).height - sample_bricks(x, y - 1).height);
      const glm::vec3 n =
          glm::normalize(glm::vec3(-kBumpDepthPx * dh_dx, -kBumpDepthPx * dh_dup, 1.0f));
      img.set(x, y, 0.5f * n + 0.5f);
    }
  }
  return img;
}

Image8 make_checker() {
  Image8 img(kTextureSize, kTextureSize, 3);
  const int cell = kTextureSize / kCheckerCells;
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x)
      img.set(x, y, ((x / cell + y / cell) % 2) ? glm::vec3(0.50f) : glm::vec3(0.90f));
  return img;
}

// The masked quad's base colour: the checker's greys in RGB and an alpha ramp from 0
// at the left edge to 1 at the right, so the MASK cutoff decides where the quad ends.
Image8 make_alpha_ramp_checker() {
  const Image8 checker = make_checker();
  Image8 img(kTextureSize, kTextureSize, 4);
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) {
      std::uint8_t* p = &img.pixels[(size_t(y) * img.width + x) * 4];
      std::copy_n(&checker.pixels[(size_t(y) * checker.width + x) * 3], 3, p);
      p[3] = std::uint8_t(std::lround(255.0 * x / (img.width - 1)));
    }
  return img;
}

// A tangent-space normal map (as make_brick_normal stores it) of smooth egg-crate bumps,
// h = sin(2 pi x / P) sin(2 pi y / P) with P half the image: its normals lean everywhere
// but along the bumps' crests and troughs, by up to 45 degrees at normalTexture.scale 1.
// Unlike the bricks, whose slopes are bevels a pixel or two wide in a small render, a
// mistake in the scale or the tangent frame changes whole areas.
Image8 make_bump_normal() {
  constexpr int kSide = 128, kPeriodPx = kSide / 2;
  constexpr double kMaxSlope = 1.0;  // |dh/dx| at most: 45 degrees
  Image8 img(kSide, kSide, 3);
  for (int y = 0; y < kSide; ++y)
    for (int x = 0; x < kSide; ++x) {
      const double a = 2.0 * kPi * (x + 0.5) / kPeriodPx, b = 2.0 * kPi * (y + 0.5) / kPeriodPx;
      const double dh_dx = kMaxSlope * std::cos(a) * std::sin(b);
      const double dh_dup = -kMaxSlope * std::sin(a) * std::cos(b);  // rows grow downwards
      const glm::vec3 n = glm::normalize(glm::vec3(float(-dh_dx), float(-dh_dup), 1.0f));
      img.set(x, y, 0.5f * n + 0.5f);
    }
  return img;
}

// A 4 x 4 grid of distinct colours, each cell shaded darker towards its lower right:
// every texel's place in the image shows, so a texture read at another UV set, or with
// another transform, shows colours or a turn the right read does not.
Image8 make_uv_grid() {
  constexpr int kCellPx = 16, kCellsPerSide = 4;
  Image8 img(kCellPx * kCellsPerSide, kCellPx * kCellsPerSide, 3);
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) {
      const std::uint32_t cell = std::uint32_t(y / kCellPx * kCellsPerSide + x / kCellPx);
      const glm::vec3 hue(0.2f + 0.8f * hash01(cell * 3u + 7u), 0.2f + 0.8f * hash01(cell * 3u + 8u),
                          0.2f + 0.8f * hash01(cell * 3u + 9u));
      const float shade = 1.0f - 0.35f * float(x % kCellPx + y % kCellPx) / float(2 * kCellPx);
      img.set(x, y, hue * shade);
    }
  return img;
}

// A metallic-roughness texture whose three channels differ, as a packed occlusion-
// roughness-metallic texture's do: R (occlusion, which the labs do not read) diagonal
// stripes, G (roughness) a ramp from 0.2 at the left to 0.9 at the right, B (metallic)
// horizontal bands of 0 and 1. Reading roughness or metallic from another channel shows.
Image8 make_packed_orm() {
  constexpr int kSide = 64, kStripePx = 8, kBandPx = 16;
  Image8 img(kSide, kSide, 3);
  for (int y = 0; y < kSide; ++y)
    for (int x = 0; x < kSide; ++x) {
      const float occlusion = ((x + y) / kStripePx) % 2 ? 1.0f : 0.35f;
      const float roughness = 0.2f + 0.7f * float(x) / float(kSide - 1);
      const float metallic = (y / kBandPx) % 2 ? 1.0f : 0.0f;
      img.set(x, y, {occlusion, roughness, metallic});
    }
  return img;
}

void write_png(const fs::path& path, const Image8& img) {
  auto out = OIIO::ImageOutput::create(path.string());
  if (!out)
    throw std::runtime_error("no PNG writer for " + path.string() + ": " + OIIO::geterror());
  OIIO::ImageSpec spec(img.width, img.height, img.channels, OIIO::TypeDesc::UINT8);
  // The bytes are PNG's own, colour not multiplied by alpha: without this OpenImageIO takes
  // them for premultiplied and divides colour by alpha on the way out, rounding differently
  // by version (alpha_ramp.png's 128 greys came out 127 in places with Debian 12's 2.4 and 128
  // with Debian 13's 2.5). Written as given, the file is the same on every version.
  spec.attribute("oiio:UnassociatedAlpha", 1);
  if (!out->open(path.string(), spec) ||
      !out->write_image(OIIO::TypeDesc::UINT8, img.pixels.data()) || !out->close())
    throw std::runtime_error("cannot write " + path.string() + ": " + out->geterror());
}

// ---------------------------------------------------------------------------
// Geometry

struct MeshData {
  std::vector<glm::vec3> positions;
  std::vector<glm::vec3> normals;
  std::vector<glm::vec2> uvs;
  std::vector<glm::vec2> uvs1;      // empty: the mesh is written without TEXCOORD_1
  std::vector<glm::vec4> tangents;  // empty: the mesh is written without TANGENT
  std::vector<std::uint32_t> indices;
};

// Per-vertex tangents from the UV layout (Lengyel's method), so mirrored UVs get w = -1.
void compute_tangents(MeshData& mesh) {
  std::vector<glm::vec3> dp_du(mesh.positions.size(), glm::vec3(0.0f));
  std::vector<glm::vec3> dp_dup(mesh.positions.size(), glm::vec3(0.0f));
  for (size_t i = 0; i + 2 < mesh.indices.size(); i += 3) {
    const std::uint32_t i0 = mesh.indices[i], i1 = mesh.indices[i + 1], i2 = mesh.indices[i + 2];
    const glm::vec3 e1 = mesh.positions[i1] - mesh.positions[i0];
    const glm::vec3 e2 = mesh.positions[i2] - mesh.positions[i0];
    // Second component is "up" in the image (decreasing glTF v), where the map's +Y points.
    const glm::vec2 d1(mesh.uvs[i1].x - mesh.uvs[i0].x, mesh.uvs[i0].y - mesh.uvs[i1].y);
    const glm::vec2 d2(mesh.uvs[i2].x - mesh.uvs[i0].x, mesh.uvs[i0].y - mesh.uvs[i2].y);
    const float det = d1.x * d2.y - d2.x * d1.y;
    if (std::abs(det) < 1e-12f) continue;  // degenerate UVs say nothing about the tangent
    const glm::vec3 s = (e1 * d2.y - e2 * d1.y) / det;
    const glm::vec3 t = (e2 * d1.x - e1 * d2.x) / det;
    for (std::uint32_t v : {i0, i1, i2}) {
      dp_du[v] += s;
      dp_dup[v] += t;
    }
  }
  mesh.tangents.resize(mesh.positions.size());
  for (size_t v = 0; v < mesh.positions.size(); ++v) {
    const glm::vec3 n = mesh.normals[v];
    const glm::vec3 t = glm::normalize(dp_du[v] - n * glm::dot(n, dp_du[v]));  // Gram-Schmidt
    const float w = glm::dot(glm::cross(n, t), dp_dup[v]) < 0.0f ? -1.0f : 1.0f;
    mesh.tangents[v] = glm::vec4(t, w);
  }
}

// A rectangle centred on the local origin. `right` and `up` are unit vectors in its plane;
// the CCW front face looks along cross(right, up). The image's top edge lies along +up and
// its left edge along -right, or along +right when mirror_u is set.
MeshData make_quad(glm::vec3 right, glm::vec3 up, glm::vec2 size, glm::vec2 uv_repeat,
                   bool mirror_u) {
  MeshData mesh;
  const glm::vec3 normal = glm::normalize(glm::cross(right, up));
  const glm::vec2 corners[4] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};  // BL, BR, TR, TL
  for (const glm::vec2& c : corners) {
    mesh.positions.push_back(right * ((c.x - 0.5f) * size.x) + up * ((c.y - 0.5f) * size.y));
    mesh.normals.push_back(normal);
    const float u = mirror_u ? 1.0f - c.x : c.x;
    mesh.uvs.emplace_back(u * uv_repeat.x, (1.0f - c.y) * uv_repeat.y);
  }
  mesh.indices = {0, 1, 2, 0, 2, 3};
  compute_tangents(mesh);
  return mesh;
}

// UV sphere around the origin: u follows the longitude so the image reads left to right
// seen from outside (u = 0.5 at +Z, the seam at -Z), v = 0 at the north pole (+Y). Tangents are
// analytic (the direction of d position / du), which stays exact at the poles and along the seam.
MeshData make_sphere(float radius, int segments, int rings, glm::vec2 uv_repeat,
                     bool with_tangents) {
  MeshData mesh;
  const int columns = segments + 1;  // the seam column is duplicated for the UV wrap
  for (int r = 0; r <= rings; ++r) {
    const float v = float(r) / float(rings);
    const double theta = kPi * v;
    for (int s = 0; s <= segments; ++s) {
      // Pole vertices take their triangle's centre u, which limits the pinch distortion.
      const bool pole = (r == 0 || r == rings);
      const float u = (float(s) + (pole ? 0.5f : 0.0f)) / float(segments);
      const double phi = 2.0 * kPi * (u - 0.5);
      const glm::vec3 n(float(std::sin(theta) * std::sin(phi)), float(std::cos(theta)),
                        float(std::sin(theta) * std::cos(phi)));
      mesh.positions.push_back(radius * n);
      mesh.normals.push_back(n);
      mesh.uvs.emplace_back(u * uv_repeat.x, v * uv_repeat.y);
      if (with_tangents)
        mesh.tangents.emplace_back(float(std::cos(phi)), 0.0f, float(-std::sin(phi)), 1.0f);
    }
  }
  // a-b on the upper ring, c-d below. The pole rows collapse to one triangle per segment,
  // which leaves the last vertex of each pole row unreferenced (kept for a regular grid).
  for (int r = 0; r < rings; ++r) {
    for (int s = 0; s < segments; ++s) {
      const std::uint32_t a = std::uint32_t(r * columns + s), b = a + 1;
      const std::uint32_t c = a + std::uint32_t(columns), d = c + 1;
      if (r == 0)
        mesh.indices.insert(mesh.indices.end(), {a, c, d});
      else if (r == rings - 1)
        mesh.indices.insert(mesh.indices.end(), {a, c, b});
      else
        mesh.indices.insert(mesh.indices.end(), {a, c, d, a, d, b});
    }
  }
  return mesh;
}

// Rotation that turns a node's local -Z towards `target`, keeping +Y up (cameras, spots).
glm::dquat look_at_rotation(glm::dvec3 eye, glm::dvec3 target) {
  return glm::quatLookAtRH(glm::normalize(target - eye), glm::dvec3(0.0, 1.0, 0.0));
}

// ---------------------------------------------------------------------------
// glTF assembly

// Accessor indices of one uploaded MeshData; several meshes (materials) may share them.
struct Geometry {
  int position = -1;
  int normal = -1;
  int texcoord = -1;
  int texcoord1 = -1;  // TEXCOORD_1; -1: none
  int tangent = -1;
  int color = -1;  // COLOR_0; -1: none (white)
  int indices = -1;
};

// How a material reads one of its textures: glTF's texCoord (which UV set) and, where
// `transformed`, a KHR_texture_transform (offset, rotation in radians, scale).
struct TextureUv {
  int tex_coord = 0;
  bool transformed = false;
  glm::dvec2 offset{0.0};
  double rotation = 0.0;
  glm::dvec2 scale{1.0};
};

struct MaterialDesc {
  std::string name;
  glm::dvec4 base_color{1.0};
  double metallic = 0.0;
  double roughness = 0.5;
  int base_color_texture = -1;
  int normal_texture = -1;
  double normal_scale = 1.0;
  glm::dvec3 emissive{0.0};
  double emissive_strength = 1.0;  // other than 1: KHR_materials_emissive_strength
  int emissive_texture = -1;
  int metallic_roughness_texture = -1;  // glTF: roughness in G, metallic in B (R is free: occlusion)
  TextureUv base_color_uv, metallic_roughness_uv, normal_uv, emissive_uv;
  std::string alpha_mode = "OPAQUE";  // glTF alphaMode: OPAQUE, MASK or BLEND
  double alpha_cutoff = 0.5;          // glTF's default; written only for MASK
  bool double_sided = false;
};

struct NodeDesc {
  std::string name;
  glm::dvec3 translation{0.0};
  glm::dquat rotation{1.0, 0.0, 0.0, 0.0};  // glm's constructor order: w, x, y, z
  glm::dvec3 scale{1.0};
  int mesh = -1;
};

const glm::dquat kNoRotation(1.0, 0.0, 0.0, 0.0);
const glm::dvec3 kUnitScale(1.0);
const glm::dvec3 kWhite(1.0);

// Adding +0.0 turns -0.0 into 0.0, so the JSON never shows "-0.0".
double tidy(double v) { return v + 0.0; }
std::vector<double> to_vector(glm::dvec3 v) { return {tidy(v.x), tidy(v.y), tidy(v.z)}; }
std::vector<double> to_vector(glm::dvec4 v) { return {tidy(v.x), tidy(v.y), tidy(v.z), tidy(v.w)}; }

// Builds one glTF model whose vertex and index data live in a single buffer.
class SceneBuilder {
 public:
  explicit SceneBuilder(std::string name) : name_(std::move(name)) {
    model_.asset.version = "2.0";
    model_.asset.generator = "kit-scenes";
    model_.buffers.emplace_back();
    model_.buffers[0].uri = name_ + ".bin";
    tinygltf::Sampler sampler;  // trilinear + repeat, shared by every texture
    sampler.magFilter = TINYGLTF_TEXTURE_FILTER_LINEAR;
    sampler.minFilter = TINYGLTF_TEXTURE_FILTER_LINEAR_MIPMAP_LINEAR;
    model_.samplers.push_back(sampler);
    model_.scenes.emplace_back();
    model_.scenes[0].name = name_;
    model_.defaultScene = 0;
  }

  Geometry add_geometry(const MeshData& mesh) {
    Geometry g;
    glm::vec3 lo = mesh.positions.front(), hi = mesh.positions.front();
    for (const glm::vec3& p : mesh.positions) {
      lo = glm::min(lo, p);
      hi = glm::max(hi, p);
    }
    g.position = add_accessor(mesh.positions, TINYGLTF_TYPE_VEC3, TINYGLTF_COMPONENT_TYPE_FLOAT,
                              TINYGLTF_TARGET_ARRAY_BUFFER);
    model_.accessors[g.position].minValues = to_vector(glm::dvec3(lo));  // required for POSITION
    model_.accessors[g.position].maxValues = to_vector(glm::dvec3(hi));
    g.normal = add_accessor(mesh.normals, TINYGLTF_TYPE_VEC3, TINYGLTF_COMPONENT_TYPE_FLOAT,
                            TINYGLTF_TARGET_ARRAY_BUFFER);
    g.texcoord = add_accessor(mesh.uvs, TINYGLTF_TYPE_VEC2, TINYGLTF_COMPONENT_TYPE_FLOAT,
                              TINYGLTF_TARGET_ARRAY_BUFFER);
    if (!mesh.uvs1.empty())
      g.texcoord1 = add_accessor(mesh.uvs1, TINYGLTF_TYPE_VEC2, TINYGLTF_COMPONENT_TYPE_FLOAT,
                                 TINYGLTF_TARGET_ARRAY_BUFFER);
    if (!mesh.tangents.empty())
      g.tangent = add_accessor(mesh.tangents, TINYGLTF_TYPE_VEC4, TINYGLTF_COMPONENT_TYPE_FLOAT,
                               TINYGLTF_TARGET_ARRAY_BUFFER);
    g.indices =
        add_accessor(mesh.indices, TINYGLTF_TYPE_SCALAR, TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT,
                     TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER);
    return g;
  }

  int add_mesh(const std::string& name, const Geometry& g, int material) {
    tinygltf::Primitive prim;
    prim.attributes["POSITION"] = g.position;
    prim.attributes["NORMAL"] = g.normal;
    prim.attributes["TEXCOORD_0"] = g.texcoord;
    if (g.texcoord1 >= 0) prim.attributes["TEXCOORD_1"] = g.texcoord1;
    if (g.tangent >= 0) prim.attributes["TANGENT"] = g.tangent;
    if (g.color >= 0) prim.attributes["COLOR_0"] = g.color;
    prim.indices = g.indices;
    prim.material = material;
    prim.mode = TINYGLTF_MODE_TRIANGLES;
    tinygltf::Mesh mesh;
    mesh.name = name;
    mesh.primitives.push_back(prim);
    model_.meshes.push_back(mesh);
    return int(model_.meshes.size()) - 1;
  }

  // COLOR_0 for `g`, one colour a vertex: FLOAT VEC3 (alpha 1), or normalized
  // UNSIGNED_BYTE VEC4 (c / 255).
  void add_colors(Geometry& g, const std::vector<glm::vec3>& rgb) {
    g.color = add_accessor(rgb, TINYGLTF_TYPE_VEC3, TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TARGET_ARRAY_BUFFER);
  }
  void add_colors(Geometry& g, const std::vector<glm::u8vec4>& rgba) {
    g.color = add_accessor(rgba, TINYGLTF_TYPE_VEC4, TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE, TINYGLTF_TARGET_ARRAY_BUFFER);
    model_.accessors[static_cast<size_t>(g.color)].normalized = true;
  }

  // A mesh of one primitive, named `name`, and a node of the same name drawing it at
  // `translation` under `parent` (a root of the scene when parent < 0).
  int add_mesh_node(const std::string& name, glm::dvec3 translation, const Geometry& g, int material,
                    int parent = -1) {
    return add_node({name, translation, kNoRotation, kUnitScale, add_mesh(name, g, material)}, parent);
  }

  // Lists an image; write() puts the PNG next to the .gltf, which references it by uri
  // only. Called alone, it adds an image no texture uses (a loader should not decode it).
  int add_image(const std::string& file_name, const Image8& image) {
    tinygltf::Image img;
    img.name = fs::path(file_name).stem().string();
    img.uri = file_name;
    model_.images.push_back(img);
    images_.emplace_back(file_name, image);
    return int(model_.images.size()) - 1;
  }

  int add_texture(const std::string& file_name, const Image8& image) {
    tinygltf::Texture tex;
    tex.sampler = 0;
    tex.source = add_image(file_name, image);
    model_.textures.push_back(tex);
    return int(model_.textures.size()) - 1;
  }

  int add_material(const MaterialDesc& desc) {
    tinygltf::Material m;
    m.name = desc.name;
    m.doubleSided = desc.double_sided;
    m.alphaMode = desc.alpha_mode;
    m.alphaCutoff = desc.alpha_cutoff;
    m.emissiveTexture.index = desc.emissive_texture;
    m.pbrMetallicRoughness.baseColorFactor = to_vector(desc.base_color);
    m.pbrMetallicRoughness.metallicFactor = desc.metallic;
    m.pbrMetallicRoughness.roughnessFactor = desc.roughness;
    m.pbrMetallicRoughness.baseColorTexture.index = desc.base_color_texture;
    m.pbrMetallicRoughness.metallicRoughnessTexture.index = desc.metallic_roughness_texture;
    m.normalTexture.index = desc.normal_texture;
    m.normalTexture.scale = desc.normal_scale;
    set_texture_uv(m.pbrMetallicRoughness.baseColorTexture, desc.base_color_uv);
    set_texture_uv(m.pbrMetallicRoughness.metallicRoughnessTexture, desc.metallic_roughness_uv);
    set_texture_uv(m.normalTexture, desc.normal_uv);
    set_texture_uv(m.emissiveTexture, desc.emissive_uv);
    m.emissiveFactor = to_vector(desc.emissive);
    if (desc.emissive_strength != 1.0) {
      // glTF limits emissiveFactor to [0, 1]; brighter emitters need this extension.
      tinygltf::Value::Object ext{{"emissiveStrength", tinygltf::Value(desc.emissive_strength)}};
      m.extensions["KHR_materials_emissive_strength"] = tinygltf::Value(ext);
      use_extension("KHR_materials_emissive_strength");
    }
    model_.materials.push_back(m);
    return int(model_.materials.size()) - 1;
  }

  // texCoord and KHR_texture_transform of one texture reference (TextureInfo or
  // NormalTextureInfo); nothing is written for the defaults (UV set 0, no transform).
  template <typename Info>
  void set_texture_uv(Info& info, const TextureUv& uv) {
    if (info.index < 0) return;
    info.texCoord = uv.tex_coord;
    if (!uv.transformed) return;
    tinygltf::Value::Object transform{
        {"offset", tinygltf::Value(tinygltf::Value::Array{tinygltf::Value(uv.offset.x), tinygltf::Value(uv.offset.y)})},
        {"rotation", tinygltf::Value(uv.rotation)},
        {"scale", tinygltf::Value(tinygltf::Value::Array{tinygltf::Value(uv.scale.x), tinygltf::Value(uv.scale.y)})}};
    info.extensions["KHR_texture_transform"] = tinygltf::Value(transform);
    use_extension("KHR_texture_transform");
    ++transformed_textures_;
  }

  // Adds a node under `parent`, or as a root of the scene when parent < 0.
  int add_node(const NodeDesc& desc, int parent = -1) {
    tinygltf::Node node;
    node.name = desc.name;
    node.mesh = desc.mesh;
    // Identity parts are left out: glTF's defaults already mean identity.
    if (desc.translation != glm::dvec3(0.0)) node.translation = to_vector(desc.translation);
    if (desc.rotation != kNoRotation) {
      const glm::dquat& q = desc.rotation;
      node.rotation = to_vector(glm::dvec4(q.x, q.y, q.z, q.w));  // glTF order: x, y, z, w
    }
    if (desc.scale != kUnitScale) node.scale = to_vector(desc.scale);
    model_.nodes.push_back(node);
    const int index = int(model_.nodes.size()) - 1;
    if (parent < 0)
      model_.scenes[0].nodes.push_back(index);
    else
      model_.nodes[parent].children.push_back(index);
    return index;
  }

  // Intensity in candela. range 0: the property is left out (unlimited).
  void add_point_light(const std::string& name, glm::dvec3 position, glm::dvec3 color,
                       double candela, double range = 0.0) {
    tinygltf::Light light;
    light.name = name;
    light.type = "point";
    light.color = to_vector(color);
    light.intensity = candela;
    light.range = range;
    attach_light(light, {name, position, kNoRotation, kUnitScale, -1});
  }

  // A spot light shines along its node's local -Z, so it is aimed like a camera.
  void add_spot_light(const std::string& name, glm::dvec3 position, glm::dvec3 target,
                      glm::dvec3 color, double candela, double inner_cone, double outer_cone,
                      double range = 0.0) {
    tinygltf::Light light;
    light.name = name;
    light.type = "spot";
    light.color = to_vector(color);
    light.intensity = candela;
    light.range = range;
    light.spot.innerConeAngle = inner_cone;
    light.spot.outerConeAngle = outer_cone;
    attach_light(light, {name, position, look_at_rotation(position, target), kUnitScale, -1});
  }

  // A directional light shines along its node's local -Z, `direction` here; its
  // intensity is an illuminance (lux). Its node's position changes nothing (glTF),
  // which lets a scene put it where treating it as a point light shows.
  void add_directional_light(const std::string& name, glm::dvec3 node_position, glm::dvec3 direction,
                             glm::dvec3 color, double lux) {
    tinygltf::Light light;
    light.name = name;
    light.type = "directional";
    light.color = to_vector(color);
    light.intensity = lux;
    attach_light(light, {name, node_position, look_at_rotation(node_position, node_position + direction),
                         kUnitScale, -1});
  }

  // No aspect ratio: the renderer uses its viewport's.
  void add_camera(glm::dvec3 eye, glm::dvec3 target, double yfov) {
    tinygltf::Camera cam;
    cam.name = "camera";
    cam.type = "perspective";
    cam.perspective.yfov = yfov;
    cam.perspective.znear = kZNear;
    cam.perspective.zfar = kZFar;
    model_.cameras.push_back(cam);
    const int node = add_node({"camera", eye, look_at_rotation(eye, target), kUnitScale, -1});
    model_.nodes[node].camera = int(model_.cameras.size()) - 1;
  }

  // Writes OUT_DIR/<name>/<name>.gltf, <name>.bin and the PNG textures.
  void write(const fs::path& out_dir) const {
    const fs::path dir = out_dir / name_;
    std::error_code ec;
    fs::create_directories(dir, ec);
    if (ec) throw std::runtime_error("cannot create " + dir.string() + ": " + ec.message());
    for (const auto& [file_name, image] : images_) write_png(dir / file_name, image);

    tinygltf::TinyGLTF writer;
    // The PNGs are already written: keep tinygltf's own (stb) image writer out of it. The
    // callback must still hand back the uri, or tinygltf writes an image with no source.
    // The callback's arguments differ by version: tinygltf 2.8 (Debian 12, Ubuntu 24.04)
    // passes (..., std::string* out_uri, void* user) to a function pointer; 2.9 (Debian 13)
    // puts FsCallbacks* and URICallbacks* before those two and takes a std::function. A
    // generic lambda converts to either; out_uri is the next to last argument in both.
    writer.SetImageWriter(
        [](const std::string*, const std::string*, const tinygltf::Image* image, bool, auto... rest) {
          std::string* out_uri = std::get<sizeof...(rest) - 2>(std::forward_as_tuple(rest...));
          *out_uri = image->uri;
          return true;
        },
        nullptr);
    const fs::path gltf = dir / (name_ + ".gltf");
    if (!writer.WriteGltfSceneToFile(&model_, gltf.string(), /*embedImages=*/false,
                                     /*embedBuffers=*/false, /*prettyPrint=*/true,
                                     /*writeBinary=*/false))
      throw std::runtime_error("cannot write " + gltf.string());
    check_written(gltf);
  }

  // Reads the written file back as JSON and checks that the writer kept what the kit put in:
  // every array's length, and each light attached to a node. A tinygltf that drops a part
  // (2.9 dropped the nodes' lights, see set_node_light) then fails the build by name instead
  // of leaving scenes that render differently on one distribution.
  void check_written(const fs::path& gltf) const {
    std::ifstream in(gltf);
    const nlohmann::json doc = nlohmann::json::parse(in, nullptr, /*allow_exceptions=*/false);
    if (doc.is_discarded()) throw std::runtime_error(gltf.string() + ": the file written is not JSON");
    auto length = [&](const char* key) { return doc.contains(key) ? doc[key].size() : size_t{0}; };
    const std::pair<const char*, size_t> arrays[] = {
        {"nodes", model_.nodes.size()},         {"meshes", model_.meshes.size()},
        {"materials", model_.materials.size()}, {"textures", model_.textures.size()},
        {"images", model_.images.size()},       {"cameras", model_.cameras.size()}};
    for (const auto& [key, expected] : arrays)
      if (length(key) != expected)
        throw std::runtime_error(gltf.string() + ": tinygltf wrote " + std::to_string(length(key)) + " " + key +
                                 " of the " + std::to_string(expected) + " the scene has");
    size_t attached = 0;
    for (const nlohmann::json& node : doc.value("nodes", nlohmann::json::array()))
      if (node.contains("extensions") && node["extensions"].contains("KHR_lights_punctual")) ++attached;
    if (attached != model_.lights.size())
      throw std::runtime_error(gltf.string() + ": tinygltf wrote " + std::to_string(attached) +
                               " nodes with a KHR_lights_punctual light, and the scene has " +
                               std::to_string(model_.lights.size()) + " lights");
    // Texture references are nested objects: count the transform's key in the materials' text.
    const std::string materials = doc.value("materials", nlohmann::json::array()).dump();
    size_t transforms = 0;
    for (size_t at = materials.find("\"KHR_texture_transform\""); at != std::string::npos;
         at = materials.find("\"KHR_texture_transform\"", at + 1))
      ++transforms;
    if (transforms != transformed_textures_)
      throw std::runtime_error(gltf.string() + ": tinygltf wrote " + std::to_string(transforms) +
                               " KHR_texture_transform objects, and the scene has " +
                               std::to_string(transformed_textures_));
  }

 private:
  // Appends `data` to the buffer as its own tightly packed bufferView.
  template <typename T>
  int add_accessor(const std::vector<T>& data, int type, int component_type, int target) {
    std::vector<unsigned char>& bytes = model_.buffers[0].data;
    const size_t offset = bytes.size();  // every element is made of 4-byte values: aligned
    const size_t length = data.size() * sizeof(T);
    bytes.resize(offset + length);
    std::memcpy(bytes.data() + offset, data.data(), length);

    tinygltf::BufferView view;
    view.buffer = 0;
    view.byteOffset = offset;
    view.byteLength = length;
    view.target = target;
    model_.bufferViews.push_back(view);

    tinygltf::Accessor acc;
    acc.bufferView = int(model_.bufferViews.size()) - 1;
    acc.componentType = component_type;
    acc.type = type;
    acc.count = data.size();
    model_.accessors.push_back(acc);
    return int(model_.accessors.size()) - 1;
  }

  void attach_light(const tinygltf::Light& light, const NodeDesc& node) {
    model_.lights.push_back(light);
    const int index = add_node(node);
    const int light_index = int(model_.lights.size()) - 1;
    tinygltf::Value::Object ext{{"light", tinygltf::Value(light_index)}};
    model_.nodes[index].extensions["KHR_lights_punctual"] = tinygltf::Value(ext);
    set_node_light(model_.nodes[index], light_index, 0);
    use_extension("KHR_lights_punctual");
  }

  // tinygltf 2.9 (Debian 13) has Node::light and writes a node's KHR_lights_punctual from
  // it alone: with light = -1 it erases the extension written above, and every scene's
  // lights were left attached to no node (so lit stages used the default rig instead).
  // tinygltf 2.8 (Debian 12, Ubuntu 24.04) has no such field and writes the extension.
  template <typename Node>
  static auto set_node_light(Node& node, int light, int) -> decltype(node.light = light, void()) {
    node.light = light;
  }
  template <typename Node>
  static void set_node_light(Node&, int, long) {}

  void use_extension(const std::string& ext) {
    auto& used = model_.extensionsUsed;
    if (std::find(used.begin(), used.end(), ext) == used.end()) used.push_back(ext);
  }

  std::string name_;
  tinygltf::Model model_;
  size_t transformed_textures_ = 0;  // texture references given a KHR_texture_transform
  std::vector<std::pair<std::string, Image8>> images_;
};

struct Textures {
  Image8 checker = make_checker();
  Image8 brick_color = make_brick_color();
  Image8 brick_normal = make_brick_normal();
};

// Plain grey with the brick normal map: the bricks show up through shading alone.
MaterialDesc normal_mapped_grey(int normal_texture) {
  MaterialDesc m;
  m.name = "normal_mapped_grey";
  m.base_color = glm::dvec4(0.75, 0.75, 0.75, 1.0);
  m.roughness = 0.5;
  m.normal_texture = normal_texture;
  m.normal_scale = 1.0;
  return m;
}

// ---------------------------------------------------------------------------
// Scenes

SceneBuilder build_default_scene(const Textures& tex) {
  SceneBuilder b("default");
  const glm::vec3 x(1, 0, 0), y(0, 1, 0), z(0, 0, 1);

  // Floor: 10 x 10 m; the 4-cell checker repeats 5 times, so each square is 0.5 m.
  MaterialDesc floor_mat;
  floor_mat.name = "floor_checker";
  floor_mat.roughness = 0.8;
  floor_mat.base_color_texture = b.add_texture("checker.png", tex.checker);
  const Geometry floor = b.add_geometry(make_quad(x, -z, {10, 10}, {5, 5}, false));
  b.add_mesh_node("floor", {0, 0, 0}, floor, b.add_material(floor_mat));

  // Back wall: 8 x 4 m at z = -4, one brick texture tile per 2 m.
  const int brick_normal = b.add_texture("brick_normal.png", tex.brick_normal);
  MaterialDesc wall_mat;
  wall_mat.name = "brick_wall";
  wall_mat.roughness = 0.9;
  wall_mat.base_color_texture = b.add_texture("brick_color.png", tex.brick_color);
  wall_mat.normal_texture = brick_normal;
  wall_mat.normal_scale = 1.0;
  const Geometry wall = b.add_geometry(make_quad(x, y, {8, 4}, {4, 2}, false));
  b.add_mesh_node("back_wall", {0, 2, -4}, wall, b.add_material(wall_mat));

  // Material spheres: parent -> row -> sphere, so the loader has to compose transforms.
  const Geometry sphere = b.add_geometry(make_sphere(0.35f, 32, 16, {2, 1}, true));
  const int parent = b.add_node({"sphere_rows", {0, 0.5, -1}});
  const int row_dielectric = b.add_node({"row_dielectric"}, parent);
  const int row_metal = b.add_node({"row_metal", {0, 0.9, 0}}, parent);
  const double roughness[5] = {0.0, 0.25, 0.5, 0.75, 1.0};
  for (int i = 0; i < 5; ++i) {
    const glm::dvec3 offset(-2.0 + i, 0.0, 0.0);
    const std::string suffix = "_r" + std::to_string(i * 25);
    MaterialDesc dielectric;
    dielectric.name = "dielectric" + suffix;
    dielectric.base_color = glm::dvec4(0.8, 0.15, 0.1, 1.0);
    dielectric.metallic = 0.0;
    dielectric.roughness = roughness[i];
    const std::string d_name = "sphere_dielectric" + suffix;
    b.add_mesh_node(d_name, offset, sphere, b.add_material(dielectric), row_dielectric);
    MaterialDesc metal;
    metal.name = "gold" + suffix;
    metal.base_color = glm::dvec4(1.0, 0.766, 0.336, 1.0);
    metal.metallic = 1.0;
    metal.roughness = roughness[i];
    const std::string m_name = "sphere_gold" + suffix;
    b.add_mesh_node(m_name, offset, sphere, b.add_material(metal), row_metal);
  }

  // Left panel facing +x, image mirrored left-right: its tangent is +z with w = -1.
  const int grey = b.add_material(normal_mapped_grey(brick_normal));
  const Geometry panel = b.add_geometry(make_quad(-z, y, {1.5, 1.5}, {1, 1}, true));
  b.add_mesh_node("mirrored_panel", {-3.5, 1.0, -1.5}, panel, grey);

  // Normal-mapped sphere without TANGENT: the loader must generate them.
  const Geometry bare = b.add_geometry(make_sphere(0.5f, 32, 16, {2, 1}, false));
  b.add_mesh_node("sphere_no_tangents", {3.2, 0.5, -1.0}, bare, grey);

  MaterialDesc glow;
  glow.name = "emissive";
  glow.base_color = glm::dvec4(0.1, 0.1, 0.1, 1.0);
  glow.emissive = glm::dvec3(1.0, 0.75, 0.5);
  glow.emissive_strength = 4.0;
  const Geometry small = b.add_geometry(make_sphere(0.1f, 16, 8, {2, 1}, true));
  b.add_mesh_node("emissive_sphere", {1.2, 0.1, 0.6}, small, b.add_material(glow));

  // No glTF range: the seeds' lights fall off by inverse square alone (kit-bench's
  // small lights carry one, bench_renderer.h).
  b.add_point_light("warm_white", {-2.0, 2.0, 0.5}, {1.0, 0.85, 0.7}, 50.0);
  b.add_point_light("cool_blue", {2.0, 1.8, 0.5}, {0.55, 0.7, 1.0}, 40.0);
  b.add_point_light("reddish", {0.5, 2.4, 0.2}, {1.0, 0.35, 0.25}, 25.0);
  b.add_spot_light("spot", {0.0, 3.5, 6.0}, {0.0, 0.95, -1.0}, kWhite, 80.0, 0.25, 0.45);

  b.add_camera({0.0, 2.2, 6.5}, {0.0, 0.8, -1.0}, 0.8);
  return b;
}

SceneBuilder build_sphere_scene() {
  SceneBuilder b("sphere");
  MaterialDesc mat;
  mat.name = "terracotta";
  mat.base_color = glm::dvec4(0.8, 0.3, 0.2, 1.0);
  mat.metallic = 0.0;
  mat.roughness = 0.4;
  const Geometry sphere = b.add_geometry(make_sphere(1.0f, 64, 32, {2, 1}, true));
  b.add_mesh_node("sphere", {0, 0, 0}, sphere, b.add_material(mat));
  b.add_point_light("light", {2, 2, 3}, kWhite, 50.0);
  b.add_camera({0, 0, 4}, {0, 0, 0}, 0.7);
  return b;
}

SceneBuilder build_grazing_scene() {
  SceneBuilder b("grazing");
  MaterialDesc mat;
  mat.name = "white_glossy";
  mat.base_color = glm::dvec4(1.0);
  mat.metallic = 0.0;
  mat.roughness = 0.3;
  const Geometry plane =
      b.add_geometry(make_quad({1, 0, 0}, {0, 0, -1}, {20, 20}, {10, 10}, false));
  b.add_mesh_node("plane", {0, 0, 0}, plane, b.add_material(mat));
  b.add_point_light("light", {0, 0.02, -2}, kWhite, 30.0);
  b.add_camera({0, 0.05, 6}, {0, 0, -10}, 0.8);
  return b;
}

// A white, fully rough floor seen at grazing angles (n.v from about 0.05 to 0.3), for
// kit-grade's lab 6: there the diffuse part of the image-based light is as large as the
// reflection, and the BRDF table's diffuse Fresnel weight C is at its smallest (about
// 0.97), so an ibl.frag that leaves C out is 3 % too bright over the whole floor. Rough,
// so that no sharp reflection of the environment's sun makes the image driver-sensitive.
SceneBuilder build_matte_scene() {
  SceneBuilder b("matte");
  MaterialDesc mat;
  mat.name = "white_matte";
  mat.base_color = glm::dvec4(0.9, 0.9, 0.9, 1.0);
  mat.metallic = 0.0;
  mat.roughness = 1.0;
  const Geometry plane =
      b.add_geometry(make_quad({1, 0, 0}, {0, 0, -1}, {30, 30}, {1, 1}, false));
  b.add_mesh_node("floor", {0, 0, -10}, plane, b.add_material(mat));
  b.add_camera({0, 0.5, 4}, {0, -0.3, -6}, 0.6);
  return b;
}

// A spot light with a wide penumbra (inner cone 10 degrees, outer 45) over a plain
// floor, seen from above: the falloff between the cones covers much of the image,
// so interpolating over the angle instead of its cosine, or a linear ramp instead
// of the smoothstep, changes thousands of pixels (the default scene's spot has a
// penumbra of 14 to 26 degrees, too narrow to tell them apart). kit-grade's lab 3.
SceneBuilder build_spot_scene() {
  SceneBuilder b("spot");
  MaterialDesc mat;
  mat.name = "grey_floor";
  mat.base_color = glm::dvec4(0.6, 0.6, 0.6, 1.0);
  mat.roughness = 0.7;
  const Geometry floor =
      b.add_geometry(make_quad({1, 0, 0}, {0, 0, -1}, {12, 12}, {1, 1}, false));
  b.add_mesh_node("floor", {0, 0, 0}, floor, b.add_material(mat));
  // Aimed almost straight down (tilted 5.7 degrees: a look-at along -Y has no up).
  b.add_spot_light("spot", {0.0, 3.0, 0.3}, {0.0, 0.0, 0.0}, kWhite, 30.0, glm::radians(10.0),
                   glm::radians(45.0));
  b.add_camera({0.0, 5.0, 6.0}, {0.0, 0.0, 1.0}, 0.8);
  return b;
}

// A sphere on a floor lit by a low sun (a directional light 26 degrees above the
// horizon) and a point light. The sun's node stands high above the sphere, where
// a point light would light the floor almost head-on: a sun treated as a point
// light at its node, lit from +direction, or dimmed with distance (lab 3) changes
// most of the image, and the point light keeps the positional path graded too.
// kit-grade's labs 2 and 3.
const glm::dvec3 kSunDirection(1.0, -0.5, -0.3);  // where its light travels (normalised by the node)
const glm::dvec3 kSunNode(0.5, 4.0, 0.5);
SceneBuilder build_sun_scene() {
  SceneBuilder b("sun");
  MaterialDesc floor_mat;
  floor_mat.name = "grey_floor";
  floor_mat.base_color = glm::dvec4(0.6, 0.6, 0.6, 1.0);
  floor_mat.roughness = 0.6;
  const Geometry floor = b.add_geometry(make_quad({1, 0, 0}, {0, 0, -1}, {12, 12}, {1, 1}, false));
  b.add_mesh_node("floor", {0, 0, 0}, floor, b.add_material(floor_mat));
  MaterialDesc ball;
  ball.name = "blue_ball";
  ball.base_color = glm::dvec4(0.25, 0.45, 0.8, 1.0);
  ball.roughness = 0.35;
  const Geometry sphere = b.add_geometry(make_sphere(1.0f, 64, 32, {2, 1}, true));
  b.add_mesh_node("sphere", {0, 1, 0}, sphere, b.add_material(ball));
  b.add_directional_light("sun", kSunNode, kSunDirection, {1.0, 0.9, 0.75}, 2.5);
  b.add_point_light("lamp", {-2.0, 1.5, 2.5}, {0.6, 0.75, 1.0}, 3.0);  // lab 2 has no falloff
  b.add_camera({0.0, 3.0, 7.0}, {0.0, 0.6, 0.0}, 0.8);
  return b;
}

// A close-up of one glossy highlight on a dark dielectric sphere (roughness 0.2):
// the highlight fills much of the view, so a mistake that changes only the
// specular peak (its height, width or clamping) changes thousands of pixels, where
// on the other scenes it covers a handful. kit-grade's lab 2.
SceneBuilder build_highlight_scene() {
  SceneBuilder b("highlight");
  MaterialDesc mat;
  mat.name = "glossy_red";
  mat.base_color = glm::dvec4(0.5, 0.1, 0.1, 1.0);
  mat.metallic = 0.0;
  mat.roughness = 0.2;
  const Geometry sphere = b.add_geometry(make_sphere(1.0f, 128, 64, {2, 1}, true));
  b.add_mesh_node("sphere", {0, 0, 0}, sphere, b.add_material(mat));
  const glm::dvec3 light(2.0, 2.0, 4.0), eye(0.0, 0.0, 3.5);
  b.add_point_light("light", light, kWhite, 1.5);  // lab 2 has no falloff: a peak of about 3
  // Aimed at the mirror point: where the normal halves the directions to the light and the eye.
  const glm::dvec3 mirror = glm::normalize(glm::normalize(light) + glm::normalize(eye));
  b.add_camera(eye, mirror, 0.2);
  return b;
}

SceneBuilder build_normal_map_scene(const Textures& tex) {
  SceneBuilder b("normalmap");
  const glm::vec3 x(1, 0, 0), y(0, 1, 0);
  const int grey =
      b.add_material(normal_mapped_grey(b.add_texture("brick_normal.png", tex.brick_normal)));

  // The quads span y in [-0.8, 1.2], so the sphere below (top at y = -0.8) stays clear.
  const Geometry quad = b.add_geometry(make_quad(x, y, {2, 2}, {1, 1}, false));
  b.add_mesh_node("quad", {-1.1, 0.2, 0}, quad, grey);
  const Geometry mirrored = b.add_geometry(make_quad(x, y, {2, 2}, {1, 1}, true));
  b.add_mesh_node("quad_mirrored", {1.1, 0.2, 0}, mirrored, grey);

  const Geometry sphere = b.add_geometry(make_sphere(0.6f, 32, 16, {2, 1}, false));
  b.add_mesh_node("sphere_no_tangents", {0, -1.4, 0}, sphere, grey);

  // A non-uniform scale only changes normals that are not aligned with its axes, so the
  // child tilts its quad 30 degrees upwards. Correct normal matrix (inverse transpose):
  // world normal ~(0, 0.756, 0.655); the plain model matrix would give ~(0, 0.277, 0.961).
  const int parent = b.add_node({"scaled_parent", {0, 1.6, 0}, kNoRotation, {2.0, 0.5, 1.0}});
  const Geometry strip = b.add_geometry(make_quad(x, y, {2, 1}, {1, 0.5}, false));
  const glm::dquat tilt = glm::angleAxis(glm::radians(-30.0), glm::dvec3(1, 0, 0));
  b.add_node({"tilted_quad", {0, 0, 0}, tilt, kUnitScale, b.add_mesh("tilted_quad", strip, grey)},
             parent);

  b.add_point_light("light", {0, 0, 2.5}, kWhite, 40.0);
  b.add_camera({0, 0, 6}, {0, 0, 0}, 0.9);
  return b;
}

// Each texture reference of a material read its own way, for kit-grade's labs 1 and 4:
//  * left, a quad with two UV sets (TEXCOORD_1 is TEXCOORD_0 turned a quarter and halved)
//    whose base colour reads UV set 0 and its metallic-roughness and emissive textures UV
//    set 1, each through a KHR_texture_transform of its own; the metallic-roughness
//    texture's three channels differ (make_packed_orm). A texture read at another's UV, at
//    UV set 0, without its transform, or from the wrong channel, shows;
//  * right, a quad with smooth bumps (make_bump_normal) at normalTexture.scale 0.4,
//    turned 35 degrees in its plane under a parent scaled (1.5, 0.8, 1): its tangent lies
//    along no axis of the scale, so a tangent taken to world space by the normal matrix
//    instead of the model matrix (which agree where the tangent lies along an axis: the
//    normalmap scene's quads) turns the bumps' slopes, and an ignored scale steepens them.
SceneBuilder build_texturing_scene(const Textures& tex) {
  SceneBuilder b("texturing");
  const glm::vec3 x(1, 0, 0), y(0, 1, 0);

  MaterialDesc uv_sets;
  uv_sets.name = "two_uv_sets";
  uv_sets.metallic = 1.0;   // the factors pass the texture's channels through
  uv_sets.roughness = 1.0;
  uv_sets.base_color_texture = b.add_texture("uv_grid.png", make_uv_grid());
  uv_sets.base_color_uv = {0, true, {0.1, 0.2}, 0.35, {1.5, 0.75}};
  uv_sets.metallic_roughness_texture = b.add_texture("packed_orm.png", make_packed_orm());
  uv_sets.metallic_roughness_uv = {1, true, {0.3, 0.0}, -0.6, {1.25, 2.0}};
  uv_sets.emissive = glm::dvec3(0.6, 0.5, 0.4);
  uv_sets.emissive_texture = b.add_texture("checker.png", tex.checker);
  uv_sets.emissive_uv = {1, true, {0.5, 0.25}, 0.0, {2.0, 2.0}};
  MeshData quad = make_quad(x, y, {2.0f, 2.0f}, {1, 1}, false);
  for (const glm::vec2& uv0 : quad.uvs) quad.uvs1.emplace_back(0.5f * uv0.y + 0.25f, 1.0f - 0.5f * uv0.x);
  b.add_mesh_node("two_uv_sets_quad", {-1.3, 0.0, 0.0}, b.add_geometry(quad), b.add_material(uv_sets));

  MaterialDesc bumpy = normal_mapped_grey(b.add_texture("bumps_normal.png", make_bump_normal()));
  bumpy.name = "scaled_normal_map";
  bumpy.normal_scale = 0.4;
  bumpy.normal_uv = {0, true, {0.25, 0.1}, 0.0, {1.0, 1.0}};
  const int parent = b.add_node({"stretched_parent", {1.2, 0.0, 0.0}, kNoRotation, {1.5, 0.8, 1.0}});
  const glm::dquat turn = glm::angleAxis(glm::radians(35.0), glm::dvec3(0, 0, 1));
  const Geometry small_quad = b.add_geometry(make_quad(x, y, {1.3f, 1.3f}, {1, 1}, false));
  b.add_node({"turned_quad", {0, 0, 0}, turn, kUnitScale, b.add_mesh("turned_quad", small_quad, b.add_material(bumpy))},
             parent);

  b.add_point_light("front", {0.0, 0.5, 3.0}, kWhite, 20.0);
  b.add_point_light("side", {3.5, 0.0, 0.8}, {1.0, 0.9, 0.8}, 10.0);  // grazes the bevels
  b.add_camera({0.0, 0.0, 4.8}, {0.0, 0.0, 0.0}, 0.8);
  return b;
}

// Two lights whose glTF range ends inside the view, over a plain floor, for kit-grade's
// lab 3: a point light 0.5 m above the floor with range 2.5 and a spot light whose range
// (2.8) ends within its outer cone. The window 1 - (d / range)^4, squared, takes each to 0
// at its range and dims it by 12 % already half way, so a falloff that drops the window
// changes most of the lit floor (no light of the other scenes has a range).
SceneBuilder build_range_scene() {
  SceneBuilder b("range");
  MaterialDesc mat;
  mat.name = "grey_floor";
  mat.base_color = glm::dvec4(0.6, 0.6, 0.6, 1.0);
  mat.roughness = 0.7;
  const Geometry floor = b.add_geometry(make_quad({1, 0, 0}, {0, 0, -1}, {12, 12}, {1, 1}, false));
  b.add_mesh_node("floor", {0, 0, 0}, floor, b.add_material(mat));
  b.add_point_light("short_point", {-1.5, 0.5, 0.0}, {1.0, 0.85, 0.7}, 8.0, 2.5);
  b.add_spot_light("short_spot", {2.0, 2.0, -0.5}, {2.1, 0.0, -0.4}, {0.7, 0.8, 1.0}, 40.0, glm::radians(20.0),
                   glm::radians(40.0), 2.8);
  b.add_camera({0.0, 5.0, 6.0}, {0.0, 0.0, 0.5}, 0.8);
  return b;
}

// glTF material features beyond the metallic-roughness factors, one object each, for
// kit-grade's labs 1 and 2 and the G-buffer tests:
//  * a sphere with a black base colour and a red emissive colour times a checker
//    emissive texture: its light is the emissive colour alone (an emission
//    multiplied by the albedo, or reduced to one scalar, or missing the texture, shows);
//  * a MASK quad whose base colour alpha ramps from 0 (left) to 1 (right), cutoff 0.3:
//    its left 30 % is no surface at all;
//  * a double-sided quad turned away from the camera: drawn only without back-face
//    culling, and lit only with its normal flipped towards the viewer;
//  * a BLEND strip with base colour alpha 0.5 across the lower edge of the three: in
//    stage 1's G-buffer with albedo.a 0.5, from stage 2 laid over them by the forward pass.
//  * two vertex-coloured strips above the rest (COLOR_0 multiplies the base colour): a
//    FLOAT VEC3 ramp from orange to blue, and a MASK strip of normalized UNSIGNED_BYTE
//    VEC4 whose alpha ramps from 64/255 to 1 under cutoff 0.5, so its left third is no
//    surface (a geometry pass that ignores COLOR_0, or its alpha, shows).
SceneBuilder build_materials_scene(const Textures& tex) {
  SceneBuilder b("materials");
  const glm::vec3 x(1, 0, 0), y(0, 1, 0);

  MaterialDesc glow;
  glow.name = "red_emitter_black_base";
  glow.base_color = glm::dvec4(0.0, 0.0, 0.0, 1.0);
  glow.roughness = 0.5;
  glow.emissive = glm::dvec3(1.0, 0.15, 0.05);
  glow.emissive_strength = 3.0;
  glow.emissive_texture = b.add_texture("checker.png", tex.checker);
  const Geometry sphere = b.add_geometry(make_sphere(0.6f, 24, 12, {2, 1}, true));
  b.add_mesh_node("emissive_sphere", {-1.6, 0.5, 0.0}, sphere, b.add_material(glow));

  MaterialDesc masked;
  masked.name = "masked_ramp";
  masked.base_color = glm::dvec4(0.3, 0.7, 1.0, 1.0);
  masked.roughness = 0.4;
  masked.base_color_texture = b.add_texture("alpha_ramp.png", make_alpha_ramp_checker());
  masked.alpha_mode = "MASK";
  masked.alpha_cutoff = 0.3;
  const Geometry quad = b.add_geometry(make_quad(x, y, {1.4f, 1.4f}, {1, 1}, false));
  b.add_mesh_node("masked_quad", {0.0, 0.5, 0.0}, quad, b.add_material(masked));

  MaterialDesc two_sided;
  two_sided.name = "double_sided_yellow";
  two_sided.base_color = glm::dvec4(0.8, 0.7, 0.2, 1.0);
  two_sided.roughness = 0.6;
  two_sided.double_sided = true;
  // Front face along -z (away from the camera), then turned 25 degrees about y.
  const Geometry back = b.add_geometry(make_quad(-x, y, {1.2f, 1.4f}, {1, 1}, false));
  const glm::dquat turn = glm::angleAxis(glm::radians(25.0), glm::dvec3(0, 1, 0));
  b.add_node({"double_sided_quad", {1.6, 0.5, 0.0}, turn, kUnitScale,
              b.add_mesh("double_sided_quad", back, b.add_material(two_sided))});

  MaterialDesc blend;
  blend.name = "blend_half";
  blend.base_color = glm::dvec4(0.9, 0.4, 0.3, 0.5);
  blend.roughness = 0.7;
  blend.alpha_mode = "BLEND";
  const Geometry strip = b.add_geometry(make_quad(x, y, {4.0f, 0.4f}, {1, 1}, false));
  // In front of the lower edge of the sphere and both quads, so the forward pass blends it over them.
  b.add_mesh_node("blend_strip", {0.0, -0.05, 0.3}, strip, b.add_material(blend));

  // make_quad's corners: bottom-left, bottom-right, top-right, top-left.
  MaterialDesc tinted;
  tinted.name = "vertex_coloured";
  tinted.base_color = glm::dvec4(0.9, 0.8, 0.7, 1.0);
  tinted.roughness = 0.5;
  Geometry ramp = b.add_geometry(make_quad(x, y, {3.0f, 0.3f}, {1, 1}, false));
  const glm::vec3 orange(1.0f, 0.45f, 0.1f), blue(0.1f, 0.35f, 1.0f);
  b.add_colors(ramp, std::vector<glm::vec3>{orange, blue, blue, orange});
  b.add_mesh_node("vertex_colour_strip", {0.0, 1.45, 0.0}, ramp, b.add_material(tinted));

  MaterialDesc tinted_mask = tinted;
  tinted_mask.name = "vertex_coloured_mask";
  tinted_mask.alpha_mode = "MASK";
  Geometry faded = b.add_geometry(make_quad(x, y, {3.0f, 0.3f}, {1, 1}, false));
  const glm::u8vec4 green_faint(40, 200, 90, 64), magenta_opaque(220, 30, 160, 255);
  b.add_colors(faded, std::vector<glm::u8vec4>{green_faint, magenta_opaque, magenta_opaque, green_faint});
  b.add_mesh_node("vertex_alpha_strip", {0.0, 1.8, 0.0}, faded, b.add_material(tinted_mask));

  b.add_point_light("light", {0.5, 2.0, 4.0}, kWhite, 3.0);  // lab 2 has no falloff
  b.add_camera({0.0, 0.6, 5.0}, {0.0, 0.3, 0.0}, 0.75);
  return b;
}

// ---------------------------------------------------------------------------
// The heavy scene: load time and memory of a model as large as students bring
// (`kit-scenes --heavy OUT_DIR`; not part of the build's scenes, since its PNGs
// take about 30 MB and several seconds to write).
constexpr int kHeavySpheresPerSide = 4;     // 16 spheres
constexpr int kHeavySphereSegments = 256;   // 256 x 128 quads: 65,536 triangles a sphere, 1,048,576 in all
constexpr int kHeavySphereRings = 128;
constexpr int kHeavyTextureSize = 2048;     // one base colour texture a sphere
constexpr int kHeavyUnusedImages = 4;       // listed by the file, used by no material

// Smooth bands of a per-texture hue: distinct textures that PNG compresses well.
Image8 make_heavy_texture(int index) {
  Image8 img(kHeavyTextureSize, kHeavyTextureSize, 3);
  const glm::vec3 hue(0.5f + 0.5f * hash01(std::uint32_t(index) * 3u), 0.5f + 0.5f * hash01(std::uint32_t(index) * 3u + 1u),
                      0.5f + 0.5f * hash01(std::uint32_t(index) * 3u + 2u));
  for (int y = 0; y < img.height; ++y) {
    const float band = 0.75f + 0.25f * float(std::sin(2.0 * kPi * 8.0 * y / img.height));
    for (int x = 0; x < img.width; ++x) img.set(x, y, hue * band);
  }
  return img;
}

SceneBuilder build_heavy_scene() {
  SceneBuilder b("heavy");
  const MeshData sphere_mesh = make_sphere(0.45f, kHeavySphereSegments, kHeavySphereRings, {1, 1}, false);
  for (int i = 0; i < kHeavySpheresPerSide * kHeavySpheresPerSide; ++i) {
    const Geometry sphere = b.add_geometry(sphere_mesh);  // a buffer of its own, as separate models have
    MaterialDesc mat;
    mat.name = "heavy_" + std::to_string(i);
    mat.roughness = 0.5;
    mat.base_color_texture = b.add_texture(mat.name + ".png", make_heavy_texture(i));
    const glm::dvec3 at(i % kHeavySpheresPerSide - 1.5, i / kHeavySpheresPerSide - 1.5, 0.0);
    b.add_mesh_node(mat.name, at, sphere, b.add_material(mat));
  }
  for (int i = 0; i < kHeavyUnusedImages; ++i)
    b.add_image("unused_" + std::to_string(i) + ".png", make_heavy_texture(100 + i));
  b.add_point_light("light", {0, 0, 4}, kWhite, 60.0);
  b.add_camera({0, 0, 7}, {0, 0, 0}, 0.8);
  return b;
}

// ---------------------------------------------------------------------------
// The crowd scene: the lighting pass's benchmark (kit-bench's `crowd` configuration,
// issue 13), laid out like a well-known deferred-shading tutorial program's scene:
// nine instances of one 19k-triangle model on a 3 x 3 grid, 32 coloured point lights
// scattered among them, no floor, at 800 x 600 (the camera is raised so all nine show).
constexpr int kCrowdModelSegments = 128;  // 128 x 76 quads, less the poles' halves: 19,200 triangles
constexpr int kCrowdModelRings = 76;
constexpr int kCrowdGridSide = 3;         // 9 instances, 172,800 triangles
constexpr double kCrowdSpacing = 3.0;     // metres between instances
constexpr int kCrowdLights = 32;
constexpr double kCrowdLightCandela = 1.5;  // each light: the 32 together expose like the default scene

SceneBuilder build_crowd_scene() {
  SceneBuilder b("crowd");
  MaterialDesc mat;
  mat.name = "crowd_model";
  mat.base_color = glm::dvec4(0.7, 0.62, 0.55, 1.0);
  mat.roughness = 0.45;
  const Geometry model = b.add_geometry(make_sphere(0.8f, kCrowdModelSegments, kCrowdModelRings, {4, 2}, false));
  const int material = b.add_material(mat);
  const double half = 0.5 * (kCrowdGridSide - 1);
  for (int i = 0; i < kCrowdGridSide * kCrowdGridSide; ++i) {
    const glm::dvec3 at(kCrowdSpacing * (i % kCrowdGridSide - half), -0.5, kCrowdSpacing * (i / kCrowdGridSide - half));
    b.add_mesh_node("crowd_" + std::to_string(i), at, model, material);
  }
  // Deterministic scatter over x, z in [-3.5, 3.5] and y in [-1.5, 2.5] (the tutorial's
  // program: y in [-4, 2], which lights its models mostly from below), colours in [0.5, 1].
  for (int i = 0; i < kCrowdLights; ++i) {
    const auto r = [i](std::uint32_t k) { return double(hash01(std::uint32_t(i) * 8u + k + 5000u)); };
    const glm::dvec3 position(7.0 * r(0) - 3.5, 4.0 * r(1) - 1.5, 7.0 * r(2) - 3.5);
    const glm::dvec3 color(0.5 + 0.5 * r(3), 0.5 + 0.5 * r(4), 0.5 + 0.5 * r(5));
    b.add_point_light("light_" + std::to_string(i), position, color, kCrowdLightCandela);
  }
  b.add_camera({0.0, 3.5, 8.0}, {0.0, -0.5, 0.0}, glm::radians(45.0));
  return b;
}

}  // namespace

// "obj-cube": an OBJ/MTL scene, as students bring them (obj_scene.h): a unit cube
// whose faces share one brick material, in Phong terms (Kd, Ks, Ns) with colour and
// normal maps, and no lights, so the tools light it with the default rig.
//   ./kit render --stage normalmap --scene build/default/scenes/obj-cube/obj-cube.obj --out cube.png
void write_obj_cube_scene(const fs::path& out_dir, const Textures& tex) {
  const fs::path dir = out_dir / "obj-cube";
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) throw std::runtime_error("cannot create " + dir.string() + ": " + ec.message());
  write_png(dir / "brick_color.png", tex.brick_color);
  write_png(dir / "brick_normal.png", tex.brick_normal);
  std::string obj = "# kit-scenes: a unit cube for the OBJ loader\nmtllib obj-cube.mtl\no cube\n";
  for (int corner = 0; corner < 8; ++corner)
    obj += std::string("v ") + ((corner & 1) ? "0.5" : "-0.5") + ((corner & 2) ? " 0.5" : " -0.5") +
           ((corner & 4) ? " 0.5" : " -0.5") + "\n";
  obj += "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n";
  obj += "vn 1 0 0\nvn -1 0 0\nvn 0 1 0\nvn 0 -1 0\nvn 0 0 1\nvn 0 0 -1\n";
  // Each face: its corners (1 + x + 2y + 4z, 1-based) counter-clockwise seen from
  // outside from the bottom left (UVs 0,0 1,0 1,1 0,1), then its normal's index.
  const int faces[6][5] = {{6, 2, 4, 8, 1}, {1, 5, 7, 3, 2}, {7, 8, 4, 3, 3},
                           {1, 2, 6, 5, 4}, {5, 6, 8, 7, 5}, {2, 1, 3, 4, 6}};
  obj += "usemtl brick\n";
  for (const auto& f : faces) {
    obj += "f";
    for (int k = 0; k < 4; ++k) obj += " " + std::to_string(f[k]) + "/" + std::to_string(k + 1) + "/" + std::to_string(f[4]);
    obj += "\n";
  }
  const std::string mtl =
      "# Phong terms: the kit turns Ns into roughness and Ks against Kd into metallic\n"
      "newmtl brick\nKd 1 1 1\nKs 0.3 0.3 0.3\nNs 40\nmap_Kd brick_color.png\nmap_Bump brick_normal.png\n";
  for (const auto& [name, text] : {std::pair<const char*, const std::string&>{"obj-cube.obj", obj}, {"obj-cube.mtl", mtl}}) {
    std::ofstream out(dir / name, std::ios::binary);
    out << text;
    if (!out) throw std::runtime_error("cannot write " + (dir / name).string());
  }
}

// ---------------------------------------------------------------------------
// Environments for lab 6 (framework/ibl.h): equirectangular, RGB half-float EXR, in
// OUT_DIR/environments/. The mapping is environment.glsl's: texel (x, y) of a
// W x H image looks along phi = ((x + 0.5) / W - 0.5) 2 pi, theta = (y + 0.5) / H pi
// from +Y, direction (sin theta sin phi, cos theta, -sin theta cos phi).

constexpr int kEnvironmentWidth = 512;
constexpr int kEnvironmentHeight = 256;
constexpr int kEnvironmentSubsamples = 4;  // per texel side: a small source's edge is antialiased

using Radiance = glm::dvec3;

glm::dvec3 environment_direction(double u, double v) {
  const double phi = (u - 0.5) * 2.0 * kPi, theta = v * kPi;
  return {std::sin(theta) * std::sin(phi), std::cos(theta), -std::sin(theta) * std::cos(phi)};
}

glm::dvec3 direction_from_angles(double elevation_degrees, double azimuth_degrees) {
  // azimuth 0 looks along -Z (the image's centre), 90 along +X
  const double e = elevation_degrees * kPi / 180.0, a = azimuth_degrees * kPi / 180.0;
  return {std::cos(e) * std::sin(a), std::sin(e), -std::cos(e) * std::cos(a)};
}

// 1 inside a cone of `radius_degrees` around `axis`, 0 outside, with a soft edge of
// `edge_degrees` (0: hard, the subsamples antialias it).
double cone(const glm::dvec3& d, const glm::dvec3& axis, double radius_degrees, double edge_degrees) {
  const double angle = std::acos(std::clamp(glm::dot(d, axis), -1.0, 1.0)) * 180.0 / kPi;
  if (edge_degrees <= 0.0) return angle <= radius_degrees ? 1.0 : 0.0;
  return std::clamp((radius_degrees + edge_degrees - angle) / edge_degrees, 0.0, 1.0);
}

template <typename RadianceAt>
void write_environment(const fs::path& path, RadianceAt radiance_at) {
  std::vector<float> pixels(static_cast<size_t>(kEnvironmentWidth) * kEnvironmentHeight * 3);
  for (int y = 0; y < kEnvironmentHeight; ++y) {
    for (int x = 0; x < kEnvironmentWidth; ++x) {
      Radiance sum(0.0);
      for (int sy = 0; sy < kEnvironmentSubsamples; ++sy)
        for (int sx = 0; sx < kEnvironmentSubsamples; ++sx)
          sum += radiance_at(environment_direction((x + (sx + 0.5) / kEnvironmentSubsamples) / kEnvironmentWidth,
                                                   (y + (sy + 0.5) / kEnvironmentSubsamples) / kEnvironmentHeight));
      sum /= double(kEnvironmentSubsamples * kEnvironmentSubsamples);
      for (int c = 0; c < 3; ++c) pixels[(static_cast<size_t>(y) * kEnvironmentWidth + x) * 3 + c] = float(sum[c]);
    }
  }
  fs::create_directories(path.parent_path());
  auto out = OIIO::ImageOutput::create(path.string());
  if (!out) throw std::runtime_error("no EXR writer for " + path.string() + ": " + OIIO::geterror());
  OIIO::ImageSpec spec(kEnvironmentWidth, kEnvironmentHeight, 3, OIIO::TypeDesc::HALF);
  spec.attribute("compression", "zip");
  if (!out->open(path.string(), spec) || !out->write_image(OIIO::TypeDesc::FLOAT, pixels.data()) || !out->close())
    throw std::runtime_error("cannot write " + path.string() + ": " + out->geterror());
}

// A sky with a small sun: the hard case for sampling. The sun's disc (1.5 degrees in
// radius) has radiance 1400, about 3000 times the sky's, so it gives an illuminance of
// about 3 on a surface facing it, comparable with the sky's own (about 1.6 overhead).
void write_sun_environment(const fs::path& path) {
  const glm::dvec3 sun = direction_from_angles(35.0, 60.0);
  write_environment(path, [&](const glm::dvec3& d) {
    if (d.y < 0.0) {  // ground: dark, warm, a little lighter towards the horizon
      const double t = std::pow(1.0 + d.y, 4.0);
      return Radiance(0.10, 0.085, 0.07) * (0.6 + 0.4 * t);
    }
    const double t = std::pow(1.0 - d.y, 3.0);  // 0 overhead, 1 at the horizon
    Radiance sky = glm::mix(Radiance(0.12, 0.25, 0.60), Radiance(0.55, 0.65, 0.80), t);
    return sky + Radiance(1400.0, 1330.0, 1200.0) * cone(d, sun, 1.5, 0.0);
  });
}

// A soft studio: a dim grey room lit by three large panels with soft edges (a key
// above front left, a fill to the right, a strip overhead behind).
void write_studio_environment(const fs::path& path) {
  const glm::dvec3 key = direction_from_angles(30.0, -40.0), fill = direction_from_angles(10.0, 80.0),
                   top = direction_from_angles(70.0, 180.0);
  write_environment(path, [&](const glm::dvec3& d) {
    const double up = 0.5 + 0.5 * d.y;
    Radiance room = glm::mix(Radiance(0.08, 0.075, 0.07), Radiance(0.30, 0.30, 0.32), up);
    room += Radiance(4.0, 3.8, 3.5) * cone(d, key, 18.0, 6.0);
    room += Radiance(1.2, 1.3, 1.5) * cone(d, fill, 22.0, 8.0);
    room += Radiance(2.0, 2.0, 2.0) * cone(d, top, 12.0, 5.0);
    return room;
  });
}

int main(int argc, char** argv) {
  const bool heavy = argc == 3 && std::string(argv[1]) == "--heavy";
  if (argc != 2 && !heavy) {
    std::cerr << "usage: kit-scenes OUT_DIR          the kit's test scenes\n"
                 "       kit-scenes --heavy OUT_DIR  OUT_DIR/heavy: 1,048,576 triangles, 16 textures of 2048x2048\n";
    return 2;
  }
  try {
    const fs::path out_dir = argv[argc - 1];
    if (heavy) {
      build_heavy_scene().write(out_dir);
      return 0;
    }
    const Textures textures;
    build_default_scene(textures).write(out_dir);
    build_sphere_scene().write(out_dir);
    build_grazing_scene().write(out_dir);
    build_normal_map_scene(textures).write(out_dir);
    build_spot_scene().write(out_dir);
    build_highlight_scene().write(out_dir);
    build_sun_scene().write(out_dir);
    build_materials_scene(textures).write(out_dir);
    build_texturing_scene(textures).write(out_dir);
    build_range_scene().write(out_dir);
    build_matte_scene().write(out_dir);
    build_crowd_scene().write(out_dir);
    write_obj_cube_scene(out_dir, textures);
    write_studio_environment(out_dir / "environments" / "studio.exr");
    write_sun_environment(out_dir / "environments" / "sun.exr");
  } catch (const std::exception& e) {
    std::cerr << "kit-scenes: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
