// The glTF loader's node tree: each draw's world matrix is parent x local along the node
// path (worked out in double from the JSON), a mirroring transform still draws the front
// faces, and EXT_mesh_gpu_instancing makes a draw of each instance.
#include <gtest/gtest.h>

#include <glm/glm.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "gl/gl.h"
#include "gltf_expected.h"
#include "images/image_io.h"
#include "kit_test.h"
#include "render/renderer.h"
#include "render/stages.h"
#include "scene/scene.h"
#include "scene_copy.h"
#include "tiny_scenes.h"

using nlohmann::json;
using namespace kit::test;  // the helpers of support/ included above

namespace {

// Every draw's world matrix is parent x local along the node path, as in the JSON.
void expect_draw_transforms_match_json(const std::string& scene_name) {
  const kit::Scene& scene = kit::test::scene(scene_name);
  json doc = scene_json(scene_name);
  std::map<std::string, glm::dmat4> worlds = world_matrices(doc);
  size_t expected_draws = 0;
  for (const json& node : doc["nodes"]) {
    if (!node.contains("mesh")) continue;
    const json& mesh = doc["meshes"][node["mesh"].get<size_t>()];
    expected_draws += mesh["primitives"].size();
    const std::string mesh_name = mesh["name"];
    bool found = false;
    for (const kit::DrawItem& d : scene.draws) {
      if (scene.primitives[static_cast<size_t>(d.primitive)].name.find("('" + mesh_name + "')") == std::string::npos) continue;
      expect_matrix_near(d.world, worlds.at(node["name"]), scene_name + " node " + node["name"].get<std::string>());
      found = true;
    }
    EXPECT_TRUE(found) << "no draw for node " << node["name"];
  }
  EXPECT_EQ(scene.draws.size(), expected_draws) << scene_name;
}

TEST(SceneLoaderValid, NodeHierarchyComposesParentTimesLocal) {
  expect_draw_transforms_match_json("default");
  expect_draw_transforms_match_json("normalmap");
  const kit::Scene& scene = kit::test::scene("default");
  // sphere_rows (0, 0.5, -1) -> row_metal (0, 0.9, 0) -> sphere_gold_r50 (0, 0, 0): world (0, 1.4, -1);
  // sphere_dielectric_r0 sits at (-2, 0, 0) under row_dielectric (identity): world (-2, 0.5, -1).
  const std::pair<std::string, glm::dvec3> spheres[] = {{"sphere_gold_r50", {0.0, 1.4, -1.0}},
                                                       {"sphere_dielectric_r0", {-2.0, 0.5, -1.0}},
                                                       {"sphere_gold_r100", {2.0, 1.4, -1.0}}};
  for (const auto& [name, expected] : spheres) {
    const kit::Primitive& p = primitive_named(scene, name);
    for (const kit::DrawItem& d : scene.draws) {
      if (&scene.primitives[static_cast<size_t>(d.primitive)] != &p) continue;
      EXPECT_NEAR(glm::distance(glm::dvec3(d.world[3]), expected), 0.0, kMatrixTolerance) << name;
    }
  }
  // Non-uniform parent scale (2, 0.5, 1) over a child rotated -30 degrees about x: the order
  // matters here. parent x local sends the child's +Y to (0, 0.5 cos 30, -sin 30).
  const kit::Scene& normalmap = kit::test::scene("normalmap");
  const kit::Primitive& tilted = primitive_named(normalmap, "tilted_quad");
  for (const kit::DrawItem& d : normalmap.draws) {
    if (&normalmap.primitives[static_cast<size_t>(d.primitive)] != &tilted) continue;
    glm::dvec3 up(glm::dmat4(d.world) * glm::dvec4(0, 1, 0, 0));
    EXPECT_NEAR(glm::distance(up, glm::dvec3(0.0, 0.5 * std::cos(glm::radians(30.0)), -std::sin(glm::radians(30.0)))), 0.0,
                kMatrixTolerance);
  }
}

// ---- mirrored transforms ----

TEST(SceneLoaderMirrored, NegativeDeterminantMarksTheDrawMirrored) {
  SceneCopy copy("sphere", "mirrored");
  copy.doc["nodes"][0]["scale"] = {-1.0, 1.0, 1.0};
  copy.save_json();
  EXPECT_FALSE(kit::test::scene("sphere").draws.at(0).mirrored());
  EXPECT_TRUE(kit::load_scene(copy.gltf.string()).draws.at(0).mirrored());
  // Mirrored twice (a parent mirroring in y over the child mirroring in x): not mirrored.
  copy.doc["nodes"].push_back({{"name", "mirror_parent"}, {"scale", {1.0, -1.0, 1.0}}, {"children", {0}}});
  copy.doc["scenes"][0]["nodes"][0] = copy.doc["nodes"].size() - 1;
  copy.save_json();
  EXPECT_FALSE(kit::load_scene(copy.gltf.string()).draws.at(0).mirrored());
}

// Pixels the geometry pass covers (depth below the clear value 1) for a 1 m quad
// at the origin, seen from +Z (stage 1, the reference solution's shaders).
size_t covered_pixels(const kit::Primitive& quad, const glm::mat4& world) {
  kit::test::context();
  const kit::Scene scene = kit::test::tiny_scene({quad}, {kit::test::plain_material(0.5f)}, {{0, world}}, {});
  kit::RenderSettings settings;
  settings.width = settings.height = 32;
  const kit::Stage& stage = kit::find_stage("gbuffer");
  kit::Renderer renderer(stage, kit::stage_library(stage, kit::kit_root() / "solutions"), scene, settings);
  kit::Camera camera;
  camera.position = {0.0f, 0.0f, 3.0f};
  camera.view = glm::lookAt(camera.position, glm::vec3(0.0f), glm::vec3(0, 1, 0));
  renderer.render(kit::frame_camera(camera, 1.0f));
  GLint front_face = 0;
  glGetIntegerv(GL_FRONT_FACE, &front_face);
  EXPECT_EQ(front_face, GL_CCW) << "draw_scene restores GL's default winding";
  const kit::Image depth = renderer.read_view(kit::View::Depth, true);
  return static_cast<size_t>(std::count_if(depth.pixels.begin(), depth.pixels.end(), [](float d) { return d < 1.0f; }));
}

TEST(SceneLoaderMirrored, MirroredQuadStillFacesTheCamera) {
  const kit::Primitive quad = kit::test::quad_primitive({1, 0, 0}, {0, 1, 0}, {1, 1});  // front face looks along +Z
  const size_t plain = covered_pixels(quad, glm::mat4(1.0f));
  EXPECT_GT(plain, 0u);
  // Witness that back faces are culled: the quad turned away covers nothing.
  EXPECT_EQ(covered_pixels(kit::test::quad_primitive({-1, 0, 0}, {0, 1, 0}, {1, 1}), glm::mat4(1.0f)), 0u);
  // Mirrored in x it still faces +Z, its triangles now clockwise on screen: drawn, all of it.
  const glm::mat4 mirror = glm::scale(glm::mat4(1.0f), glm::vec3(-1.0f, 1.0f, 1.0f));
  EXPECT_EQ(covered_pixels(quad, mirror), plain);
}

// ---- EXT_mesh_gpu_instancing ----

TEST(SceneLoaderInstancing, EachInstanceIsADrawAtNodeTimesInstanceTrs) {
  SceneCopy copy("sphere", "instancing");
  const std::vector<float> translations = {0, 0, 0, 3, 0, -1, -2.5f, 1, 4};
  const std::vector<float> rotations = {0, 0, 0, 1, 0, 0.70710678f, 0, 0.70710678f, 0.5f, 0.5f, 0.5f, 0.5f};
  const std::vector<float> scales = {1, 1, 1, 2, 2, 2, 0.5f, 1, 3};
  auto accessor = [&](const std::vector<float>& values, const char* type) {
    const size_t components = std::string(type) == "VEC4" ? 4 : 3;
    return copy.add_accessor({{"bufferView", copy.add_view(bytes_of(values))}, {"componentType", 5126},
                              {"count", values.size() / components}, {"type", type}});
  };
  json& node = copy.doc["nodes"][0];
  node["translation"] = {1.0, 2.0, 3.0};
  node["rotation"] = {0.0, 0.0, 0.38268343, 0.92387953};  // 45 degrees about z
  node["extensions"]["EXT_mesh_gpu_instancing"]["attributes"] = {
      {"TRANSLATION", accessor(translations, "VEC3")}, {"ROTATION", accessor(rotations, "VEC4")},
      {"SCALE", accessor(scales, "VEC3")}};
  copy.require_extension("EXT_mesh_gpu_instancing");
  copy.save_json();
  const kit::Scene scene = kit::load_scene(copy.gltf.string());
  ASSERT_EQ(scene.draws.size(), 3u);
  const glm::dmat4 node_world = world_matrices(copy.doc).at("sphere");
  for (size_t i = 0; i < 3; ++i) {
    const json instance = {{"translation", {translations[3 * i], translations[3 * i + 1], translations[3 * i + 2]}},
                           {"rotation", {rotations[4 * i], rotations[4 * i + 1], rotations[4 * i + 2], rotations[4 * i + 3]}},
                           {"scale", {scales[3 * i], scales[3 * i + 1], scales[3 * i + 2]}}};
    expect_matrix_near(scene.draws[i].world, node_world * local_matrix(instance), "instance " + std::to_string(i));
  }
}

TEST(SceneLoaderInstancing, InstancesBeyondTheDrawLimitAreRefused) {
  SceneCopy copy("sphere", "instancing_limit");
  // No bufferView: zeros, so a small file can ask for any count.
  const int translations = copy.add_accessor({{"componentType", 5126}, {"count", kit::kMaxSceneDraws + 1}, {"type", "VEC3"}});
  copy.doc["nodes"][0]["extensions"]["EXT_mesh_gpu_instancing"]["attributes"]["TRANSLATION"] = translations;
  copy.save_json();
  expect_scene_error(copy.gltf, "node 0 ('sphere') EXT_mesh_gpu_instancing has " + std::to_string(kit::kMaxSceneDraws + 1) +
                              " instances, more than the kit draws (" + std::to_string(kit::kMaxSceneDraws) + " draws in all)");
  copy.doc["accessors"][static_cast<size_t>(translations)]["count"] = kit::kMaxSceneDraws;  // at the limit: loads
  copy.save_json();
  EXPECT_EQ(kit::load_scene(copy.gltf.string()).draws.size(), kit::kMaxSceneDraws);
}

}  // namespace
