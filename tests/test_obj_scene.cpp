// The OBJ/MTL loader (common/scene/obj_scene.*): every test writes its own OBJ, MTL
// and PNG files, and expected values are computed from those numbers in double
// (the MTL conversion by the formulas obj_scene.cpp documents).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>

#include "base/error.h"
#include "gbuffer_layout.h"
#include "images/image_io.h"
#include "kit_test.h"
#include "kit_test_files.h"
#include "scene/obj_scene.h"
#include "scene/scene.h"
#include "images/texture_decode.h"

namespace fs = std::filesystem;

namespace {

constexpr double kFloatTolerance = 1e-6;  // a float read from text against the same number in double
constexpr double kUnitTolerance = 1e-5;   // a unit vector from float arithmetic

// Skips a test in a build without tinyobjloader (OBJ support is optional).
// The test build requires OBJ support (tests/CMakeLists.txt), so nothing here skips.
#define REQUIRE_OBJ_SUPPORT() ASSERT_TRUE(kit::obj_scenes_supported()) << "built without libtinyobjloader-dev"

// A square quad in the z = 0 plane facing +Z, corners (+-h, +-h), with UVs and one normal.
const char* const kQuadObj =
    "mtllib quad.mtl\n"
    "o quad\n"
    "v -0.5 -0.5 0\nv 0.5 -0.5 0\nv 0.5 0.5 0\nv -0.5 0.5 0\n"
    "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
    "vn 0 0 1\n"
    "usemtl paint\n"
    "f 1/1/1 2/2/1 3/3/1 4/4/1\n";

double roughness_from_ns(double ns) { return std::pow(2.0 / (std::max(ns, 0.0) + 2.0), 0.25); }
double metallic_from_kd_ks(double max_kd, double max_ks) {
  return max_ks > 0.0 ? std::clamp(1.0 - max_kd / max_ks, 0.0, 1.0) : 0.0;
}

}  // namespace

TEST(ObjScene, ExtensionIsCaseInsensitive) {
  EXPECT_TRUE(kit::is_obj_path("a/b/Model.OBJ"));
  EXPECT_TRUE(kit::is_obj_path("x.obj"));
  EXPECT_FALSE(kit::is_obj_path("x.gltf"));
  EXPECT_FALSE(kit::is_obj_path("obj"));
}

TEST(ObjScene, PositionsUvsAndNormalsFromTheFile) {
  REQUIRE_OBJ_SUPPORT();
  fs::path dir = kit::test::temp_dir("obj_scene/attributes");
  kit::test::write_file(dir / "Quad.OBJ", kQuadObj);
  kit::test::write_file(dir / "quad.mtl", "newmtl paint\nKd 0.5 0.5 0.5\n");
  const kit::Scene scene = kit::load_scene((dir / "Quad.OBJ").string());
  ASSERT_EQ(scene.primitives.size(), 1u);
  ASSERT_EQ(scene.draws.size(), 1u);
  const kit::Primitive& prim = scene.primitives[0];
  ASSERT_EQ(prim.vertices.size(), 4u);  // four corners, shared by the quad's two triangles
  ASSERT_EQ(prim.indices.size(), 6u);
  const double positions[4][3] = {{-0.5, -0.5, 0}, {0.5, -0.5, 0}, {0.5, 0.5, 0}, {-0.5, 0.5, 0}};
  const double obj_uvs[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  for (int corner = 0; corner < 4; ++corner) {
    // Find the vertex at this position; its UV and normal must be the file's (v flipped).
    auto it = std::find_if(prim.vertices.begin(), prim.vertices.end(), [&](const kit::Vertex& v) {
      return std::abs(v.position.x - positions[corner][0]) < kFloatTolerance &&
             std::abs(v.position.y - positions[corner][1]) < kFloatTolerance;
    });
    ASSERT_NE(it, prim.vertices.end()) << "corner " << corner;
    EXPECT_NEAR(it->position.z, positions[corner][2], kFloatTolerance);
    EXPECT_NEAR(it->texcoord.x, obj_uvs[corner][0], kFloatTolerance);
    EXPECT_NEAR(it->texcoord.y, 1.0 - obj_uvs[corner][1], kFloatTolerance) << "OBJ's v grows up, the kit's down";
    EXPECT_NEAR(it->normal.x, 0.0, kFloatTolerance);
    EXPECT_NEAR(it->normal.y, 0.0, kFloatTolerance);
    EXPECT_NEAR(it->normal.z, 1.0, kFloatTolerance);
    EXPECT_NEAR(std::sqrt(double(glm::dot(glm::vec3(it->tangent), glm::vec3(it->tangent)))), 1.0, kUnitTolerance);
  }
  // u grows along +x: the generated tangent is +x.
  EXPECT_NEAR(prim.vertices[0].tangent.x, 1.0, kUnitTolerance);
  EXPECT_NEAR(scene.bounds_min.x, -0.5, kFloatTolerance);
  EXPECT_NEAR(scene.bounds_max.y, 0.5, kFloatTolerance);
  EXPECT_FALSE(scene.camera.has_value());
  EXPECT_TRUE(scene.lights.empty());
}

TEST(ObjScene, FacesWithoutNormalsGetTheirPlanesNormal) {
  REQUIRE_OBJ_SUPPORT();
  fs::path dir = kit::test::temp_dir("obj_scene/flat");
  // A tilted quad, wound counter-clockwise seen from its front.
  const double corners[4][3] = {{0, 0, 0}, {2, 0, 1}, {2, 3, 1}, {0, 3, 0}};
  std::string obj;
  for (const auto& c : corners)
    obj += "v " + std::to_string(c[0]) + " " + std::to_string(c[1]) + " " + std::to_string(c[2]) + "\n";
  obj += "f 1 2 3 4\n";
  kit::test::write_file(dir / "tilted.obj", obj);
  const kit::Scene scene = kit::load_scene((dir / "tilted.obj").string());
  ASSERT_EQ(scene.primitives.size(), 1u);
  const kit::Primitive& prim = scene.primitives[0];
  ASSERT_EQ(prim.indices.size(), 6u);
  // The plane's normal in double: cross(b - a, d - a), normalised.
  const double e1[3] = {corners[1][0] - corners[0][0], corners[1][1] - corners[0][1], corners[1][2] - corners[0][2]};
  const double e2[3] = {corners[3][0] - corners[0][0], corners[3][1] - corners[0][1], corners[3][2] - corners[0][2]};
  double n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
  const double length = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
  for (double& c : n) c /= length;
  for (const kit::Vertex& v : prim.vertices) {
    EXPECT_NEAR(v.normal.x, n[0], kUnitTolerance);
    EXPECT_NEAR(v.normal.y, n[1], kUnitTolerance);
    EXPECT_NEAR(v.normal.z, n[2], kUnitTolerance);
  }
  // No usemtl: the documented default material, a light grey dielectric.
  ASSERT_GE(prim.material, 0);
  const kit::Material& m = scene.materials[static_cast<size_t>(prim.material)];
  EXPECT_FLOAT_EQ(m.metallic_factor, 0.0f);
  EXPECT_FLOAT_EQ(m.base_color_factor.r, 0.8f);
}

// `v x y z r g b` colours the vertex like glTF's COLOR_0 (alpha 1); a file without
// them, or a vertex without one in a file that has some, is white.
TEST(ObjScene, VertexColoursFromTheFile) {
  REQUIRE_OBJ_SUPPORT();
  fs::path dir = kit::test::temp_dir("obj_scene/vertex_colours");
  const double colors[3][3] = {{1.0, 0.25, 0.0}, {0.125, 0.5, 0.75}, {0.3, 0.6, 0.9}};
  kit::test::write_file(dir / "painted.obj",
                        "v 0 0 0 1.0 0.25 0.0\nv 1 0 0 0.125 0.5 0.75\nv 1 1 0 0.3 0.6 0.9\nv 0 1 0\nf 1 2 3 4\n");
  const kit::Scene scene = kit::load_scene((dir / "painted.obj").string());
  const kit::Primitive& prim = scene.primitives.at(0);
  bool corner_seen[4] = {false, false, false, false};
  for (const kit::Vertex& v : prim.vertices) {
    const int corner = v.position.x == 0.0f ? (v.position.y == 0.0f ? 0 : 3) : (v.position.y == 0.0f ? 1 : 2);
    for (int c = 0; c < 3; ++c) {
      const double expected = corner == 3 ? 1.0 : colors[corner][c];
      EXPECT_NEAR(v.color[c] / 65535.0, expected, 0.5 / 65535.0) << "corner " << corner << " channel " << c;
    }
    EXPECT_EQ(v.color[3], 65535) << "alpha 1";
    corner_seen[corner] = true;
  }
  for (int corner = 0; corner < 4; ++corner) EXPECT_TRUE(corner_seen[corner]) << "corner " << corner;
  kit::test::write_file(dir / "Quad.obj", kQuadObj);
  const kit::Scene plain = kit::load_scene((dir / "Quad.obj").string());
  for (const kit::Vertex& v : plain.primitives.at(0).vertices) EXPECT_EQ(v.color, glm::u16vec4(65535));
}

TEST(ObjScene, MaterialsFollowTheDocumentedConversion) {
  REQUIRE_OBJ_SUPPORT();
  fs::path dir = kit::test::temp_dir("obj_scene/materials");
  kit::test::write_file(dir / "m.obj",
                        "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\n"
                        "usemtl phong\nf 1 2 3\nusemtl clear\nf 1 2 3\nusemtl pbr\nf 1 2 3\n");
  kit::test::write_file(dir / "m.mtl",
                        "# Phong: metallic and roughness from Ks, Kd and Ns\n"
                        "newmtl phong\nKd 0.2 0.4 0.6\nKs 0.9 0.8 0.7\nKe 1 2 3\nd 0.5\nNs 250\n"
                        "newmtl clear\nKd 0.3 0.3 0.1\nKs 0 0 0\nTr 0.25\nNs 0\n"
                        "newmtl pbr\nKd 0.7 0.1 0.2\nKs 1 1 1\nPr 0.3\nPm 0.9\n");
  const kit::Scene scene = kit::load_scene((dir / "m.obj").string());
  ASSERT_EQ(scene.materials.size(), 3u);

  const kit::Material& phong = scene.materials[0];
  EXPECT_EQ(phong.name, "phong");
  const double kd[3] = {0.2, 0.4, 0.6}, ks[3] = {0.9, 0.8, 0.7};
  const double metallic = metallic_from_kd_ks(0.6, 0.9);
  EXPECT_NEAR(phong.metallic_factor, metallic, kFloatTolerance);
  EXPECT_NEAR(phong.roughness_factor, roughness_from_ns(250.0), kFloatTolerance);
  for (int c = 0; c < 3; ++c)
    EXPECT_NEAR(phong.base_color_factor[c], kd[c] + (ks[c] - kd[c]) * metallic, kFloatTolerance) << "channel " << c;
  EXPECT_NEAR(phong.base_color_factor.a, 0.5, kFloatTolerance);
  EXPECT_NEAR(phong.emissive.x, 1.0, kFloatTolerance);
  EXPECT_NEAR(phong.emissive.y, 2.0, kFloatTolerance);
  EXPECT_NEAR(phong.emissive.z, 3.0, kFloatTolerance);

  const kit::Material& clear = scene.materials[1];
  EXPECT_NEAR(clear.metallic_factor, 0.0, kFloatTolerance);
  EXPECT_NEAR(clear.roughness_factor, roughness_from_ns(0.0), kFloatTolerance);
  EXPECT_NEAR(clear.base_color_factor.r, 0.3, kFloatTolerance);
  EXPECT_NEAR(clear.base_color_factor.b, 0.1, kFloatTolerance);
  EXPECT_NEAR(clear.base_color_factor.a, 1.0 - 0.25, kFloatTolerance) << "Tr is 1 - d";
  // d < 1 (or Tr > 0) is see-through: drawn as glTF BLEND by the forward pass; d 1 stays opaque.
  EXPECT_EQ(phong.alpha_mode, KIT_ALPHA_BLEND);
  EXPECT_EQ(clear.alpha_mode, KIT_ALPHA_BLEND);

  const kit::Material& pbr = scene.materials[2];
  EXPECT_NEAR(pbr.roughness_factor, 0.3, kFloatTolerance) << "Pr wins over Ns";
  EXPECT_NEAR(pbr.metallic_factor, 0.9, kFloatTolerance) << "Pm wins over Ks";
  EXPECT_NEAR(pbr.base_color_factor.r, 0.7, kFloatTolerance) << "with Pm, Kd stays the base colour";
  EXPECT_NEAR(pbr.base_color_factor.g, 0.1, kFloatTolerance);
  EXPECT_EQ(pbr.alpha_mode, KIT_ALPHA_OPAQUE);
  ASSERT_EQ(scene.primitives.size(), 3u);
}

TEST(ObjScene, TexturesLoadWithTheirOptions) {
  REQUIRE_OBJ_SUPPORT();
  fs::path dir = kit::test::temp_dir("obj_scene/textures");
  // 2x2, top row red, bottom row blue: the decoded image keeps the top row first.
  kit::Image colour(2, 2, 3);
  for (int x = 0; x < 2; ++x) {
    colour.at(x, 0, 0) = 1.0f;
    colour.at(x, 1, 2) = 1.0f;
  }
  fs::create_directories(dir / "maps");
  kit::write_image((dir / "maps" / "colour.png").string(), colour);
  kit::write_image((dir / "flat.png").string(), kit::Image(1, 1, 3));
  kit::test::write_file(dir / "t.obj", "mtllib t.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\n"
                                       "usemtl textured\nf 1/1 2/2 3/3\n");
  kit::test::write_file(dir / "t.mtl", "newmtl textured\nKd 1 1 1\nmap_Kd maps\\colour.png\n"
                                       "map_Bump -bm 0.5 flat.png\nmap_Ke maps/colour.png\nmap_Ks missing.png\n");
  const kit::Scene scene = kit::load_scene((dir / "t.obj").string());
  ASSERT_EQ(scene.materials.size(), 1u);
  const kit::Material& m = scene.materials[0];
  const int base_color = m.texture(KIT_UNIT_BASE_COLOR).image;
  ASSERT_GE(base_color, 0);
  EXPECT_EQ(m.texture(KIT_UNIT_EMISSIVE).image, base_color) << "one image per file, however many maps name it";
  EXPECT_EQ(m.emissive, glm::vec3(1.0f)) << "map_Ke without Ke: the map alone";
  ASSERT_GE(m.texture(KIT_UNIT_NORMAL_MAP).image, 0);
  EXPECT_FLOAT_EQ(m.normal_scale, 0.5f);
  const kit::ImageRgba8 image = kit::decode_scene_image(scene.images[static_cast<size_t>(base_color)]);
  ASSERT_EQ(image.width, 2);
  EXPECT_EQ(image.pixels[0], 255);  // top-left red
  EXPECT_EQ(image.pixels[2], 0);
  EXPECT_EQ(image.pixels[2 * 4 + 2], 255);  // bottom-left blue
  // map_Ks is not read: a warning names it.
  const bool warned = std::any_of(scene.warnings.begin(), scene.warnings.end(),
                                  [](const std::string& w) { return w.find("map_Ks 'missing.png'") != std::string::npos; });
  EXPECT_TRUE(warned);
}

// A map's -o and -s options (OBJ's UVs, v up) reach the texture as its transform of
// the kit's UVs (v down): at each corner, the UV it samples is the option's, flipped.
// Written with all three values, as exporters write them (tinyobjloader reads three).
TEST(ObjScene, MapOffsetAndScaleBecomeTheTexturesTransform) {
  REQUIRE_OBJ_SUPPORT();
  fs::path dir = kit::test::temp_dir("obj_scene/texture_options");
  kit::write_image((dir / "tile.png").string(), kit::Image(1, 1, 3));
  kit::test::write_file(dir / "quad.obj", std::string(kQuadObj));
  kit::test::write_file(dir / "quad.mtl", "newmtl paint\nKd 1 1 1\nmap_Kd -o 0.25 0.5 0 -s 2 3 1 tile.png\n"
                                          "map_Ke tile.png\n");
  const kit::Scene scene = kit::load_scene((dir / "quad.obj").string());
  ASSERT_EQ(scene.materials.size(), 1u);
  const kit::Material& m = scene.materials[0];
  size_t checked = 0;
  for (const kit::Vertex& v : scene.primitives.at(0).vertices) {
    const double u_obj = v.texcoord.x, v_obj = 1.0 - v.texcoord.y;  // the file's vt
    const glm::vec2 sampled = m.texture(KIT_UNIT_BASE_COLOR).uv.of(v);
    EXPECT_NEAR(sampled.x, 2.0 * u_obj + 0.25, kFloatTolerance);
    EXPECT_NEAR(sampled.y, 1.0 - (3.0 * v_obj + 0.5), kFloatTolerance);
    EXPECT_EQ(m.texture(KIT_UNIT_EMISSIVE).uv.of(v), v.texcoord) << "a map without options samples the vertex's UV";
    ++checked;
  }
  EXPECT_EQ(checked, 4u);
}

TEST(ObjScene, TexturePathOutsideTheFolderIsRefused) {
  REQUIRE_OBJ_SUPPORT();
  fs::path root = kit::test::temp_dir("obj_scene/escape");
  fs::path dir = root / "scene";
  kit::write_image((root / "secret.png").string(), kit::Image(1, 1, 3));
  kit::test::write_file(dir / "e.obj", "mtllib e.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl sneaky\nf 1 2 3\n");
  kit::test::write_file(dir / "e.mtl", "newmtl sneaky\nKd 1 1 1\nmap_Kd ../secret.png\n");
  const std::string message = kit::test::scene_load_error(dir / "e.obj");
  EXPECT_NE(message.find((dir / "e.obj").string()), std::string::npos) << message;
  EXPECT_NE(message.find("material 'sneaky' (e.mtl:1)"), std::string::npos) << message;
  EXPECT_NE(message.find("map_Kd '../secret.png'"), std::string::npos) << message;
  EXPECT_NE(message.find("outside the scene's folder"), std::string::npos) << message;
}

TEST(ObjScene, MtlOutsideTheFolderIsRefused) {
  REQUIRE_OBJ_SUPPORT();
  fs::path dir = kit::test::temp_dir("obj_scene/mtl_escape") / "scene";
  kit::test::write_file(dir / "e.obj", "mtllib ../elsewhere.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  const std::string message = kit::test::scene_load_error(dir / "e.obj");
  EXPECT_NE(message.find("mtllib '../elsewhere.mtl' lies outside the scene's folder"), std::string::npos) << message;
}

TEST(ObjScene, MissingMtlIsAWarning) {
  REQUIRE_OBJ_SUPPORT();
  fs::path dir = kit::test::temp_dir("obj_scene/missing_mtl");
  kit::test::write_file(dir / "m.obj", "mtllib gone.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl red\nf 1 2 3\n");
  const kit::Scene scene = kit::load_scene((dir / "m.obj").string());
  const bool warned = std::any_of(scene.warnings.begin(), scene.warnings.end(), [&](const std::string& w) {
    return w.find((dir / "m.obj").string()) != std::string::npos && w.find("mtllib 'gone.mtl': file not found") != std::string::npos;
  });
  EXPECT_TRUE(warned);
  ASSERT_EQ(scene.primitives.size(), 1u);
  const kit::Material& m = scene.materials[static_cast<size_t>(scene.primitives[0].material)];
  EXPECT_EQ(m.name, "(no material)");
}

TEST(ObjScene, BrokenFilesFailWithTheirElement) {
  REQUIRE_OBJ_SUPPORT();
  fs::path dir = kit::test::temp_dir("obj_scene/broken");
  kit::test::write_file(dir / "index.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n");
  std::string message = kit::test::scene_load_error(dir / "index.obj");
  EXPECT_NE(message.find("face 1"), std::string::npos) << message;
  EXPECT_NE(message.find("position (v) index 9 does not exist"), std::string::npos) << message;

  kit::test::write_file(dir / "normal.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//1 3//4\n");
  message = kit::test::scene_load_error(dir / "normal.obj");
  EXPECT_NE(message.find("normal (vn) index 4 does not exist"), std::string::npos) << message;

  kit::test::write_file(dir / "empty.obj", "v 0 0 0\n");
  message = kit::test::scene_load_error(dir / "empty.obj");
  EXPECT_NE(message.find("draws no triangles"), std::string::npos) << message;

  message = kit::test::scene_load_error(dir / "absent.obj");
  EXPECT_NE(message.find("not found"), std::string::npos) << message;
}

// The OBJ quad through the real pipeline: the G-buffer's albedo at the centre is Kd.
TEST(ObjScene, RendersItsKdIntoTheGBuffer) {
  REQUIRE_OBJ_SUPPORT();
  fs::path dir = kit::test::temp_dir("obj_scene/render");
  kit::test::write_file(dir / "quad.obj", kQuadObj);
  const double kd[3] = {0.25, 0.5, 0.75};
  kit::test::write_file(dir / "quad.mtl", "newmtl paint\nKd 0.25 0.5 0.75\nKs 0 0 0\n");
  kit::RenderSettings settings;
  settings.width = 64;
  settings.height = 48;
  auto renderer = kit::test::render_stage("gbuffer", (dir / "quad.obj").string(), settings);
  const kit::Image albedo = renderer->read_view(kit::View::Albedo, true);
  for (int c = 0; c < 3; ++c)
    EXPECT_NEAR(albedo.at(32, 24, c), kd[c], 1.0 / 255.0) << "channel " << c;
  EXPECT_GT(albedo.at(32, 24, 0) + albedo.at(32, 24, 1) + albedo.at(32, 24, 2), 0.0f);
}

