// The glTF loader's lights (KHR_lights_punctual: point, spot and directional, with their
// ranges) and cameras (perspective and orthographic): placed and projected as the JSON
// and glTF 2.0 say, computed here in double; invalid ones are refused by index.
#include <gtest/gtest.h>

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstddef>
#include <map>
#include <string>
#include <utility>

#include "base/error.h"
#include "gbuffer_layout.h"  // KIT_LIGHT_*
#include "gltf_expected.h"
#include "kit_test.h"
#include "scene/scene.h"
#include "scene_copy.h"

using nlohmann::json;
using namespace kit::test;  // the helpers of support/ included above

namespace {

TEST(SceneLoaderValid, DefaultSceneCountsLightsAndCamera) {
  const kit::Scene& scene = kit::test::scene("default");
  json doc = scene_json("default");
  EXPECT_EQ(scene.primitives.size(), doc["meshes"].size());  // one primitive per kit mesh
  EXPECT_EQ(scene.materials.size(), doc["materials"].size());
  EXPECT_EQ(scene.images.size(), doc["images"].size());

  const json& lights = doc["extensions"]["KHR_lights_punctual"]["lights"];
  ASSERT_EQ(scene.lights.size(), 4u);
  ASSERT_EQ(lights.size(), 4u);
  int spots = 0;
  std::map<std::string, glm::dmat4> worlds = world_matrices(doc);
  for (size_t i = 0; i < scene.lights.size(); ++i) {
    const kit::Light& l = scene.lights[i];
    const json& expected = lights[i];  // light nodes are in light order in the kit scenes
    glm::dvec3 position(worlds.at(expected["name"])[3]);
    EXPECT_NEAR(glm::distance(glm::dvec3(l.position), position), 0.0, kMatrixTolerance) << expected["name"];
    EXPECT_NEAR(l.intensity, expected["intensity"].get<double>(), 1e-6);
    EXPECT_NEAR(l.range, expected.value("range", 0.0), 1e-6);
    if (expected["type"] == "spot") {
      ++spots;
      EXPECT_EQ(l.type, KIT_LIGHT_SPOT);
      EXPECT_NEAR(l.inner_cone, expected["spot"]["innerConeAngle"].get<double>(), 1e-6);
      EXPECT_NEAR(l.outer_cone, expected["spot"]["outerConeAngle"].get<double>(), 1e-6);
      // The generator aims the spot from (0, 3.5, 6) at (0, 0.95, -1): the node's -Z.
      glm::dvec3 aim = glm::normalize(glm::dvec3(0.0, 0.95, -1.0) - position);
      EXPECT_NEAR(glm::distance(glm::dvec3(l.direction), aim), 0.0, kUnitTolerance);
    } else {
      EXPECT_EQ(l.type, KIT_LIGHT_POINT);
    }
  }
  EXPECT_EQ(spots, 1);

  ASSERT_TRUE(scene.camera.has_value());
  const json& cam = doc["cameras"][0]["perspective"];
  EXPECT_NEAR(scene.camera->yfov, cam["yfov"].get<double>(), 1e-6);
  EXPECT_NEAR(scene.camera->znear, cam["znear"].get<double>(), 1e-6);
  EXPECT_NEAR(scene.camera->zfar, cam["zfar"].get<double>(), 1e-6);
  glm::dvec3 eye(worlds.at("camera")[3]);
  EXPECT_NEAR(glm::distance(glm::dvec3(scene.camera->position), eye), 0.0, kMatrixTolerance);
  // The camera looks from (0, 2.2, 6.5) at (0, 0.8, -1): view * eye = origin, forward = -Z.
  glm::dvec4 eye_in_view = glm::dmat4(scene.camera->view) * glm::dvec4(eye, 1.0);
  EXPECT_NEAR(glm::length(glm::dvec3(eye_in_view)), 0.0, kMatrixTolerance);
  glm::dvec3 forward(glm::inverse(glm::dmat4(scene.camera->view)) * glm::dvec4(0, 0, -1, 0));
  EXPECT_NEAR(glm::distance(forward, glm::normalize(glm::dvec3(0.0, 0.8, -1.0) - eye)), 0.0, kUnitTolerance);
}

TEST(SceneLoaderErrors, NegativeLightRange) {
  SceneCopy copy("sphere", "negative_range");
  copy.doc["extensions"]["KHR_lights_punctual"]["lights"][0]["range"] = -2.0;
  copy.save_json();
  expect_scene_error(copy.gltf, "KHR_lights_punctual light 0 has range -2");
}

// A range in the file reaches the Light (lab 3's window, lights.glsl kit_range_window).
TEST(SceneLoaderValid, LightRangeIsLoaded) {
  SceneCopy copy("sphere", "light_range");
  copy.doc["extensions"]["KHR_lights_punctual"]["lights"][0]["range"] = 3.5;
  copy.save_json();
  const kit::Scene scene = kit::load_scene(copy.gltf.string());
  ASSERT_EQ(scene.lights.size(), 1u);
  EXPECT_FLOAT_EQ(scene.lights[0].range, 3.5f);
  EXPECT_EQ(kit::test::scene("sphere").lights[0].range, 0.0f) << "the kit's scenes leave range out";
}

// A node's light index is checked before it becomes an int: tinygltf's
// GetNumberAsInt converted 1e300 to int, undefined behaviour that UBSan reported
// (an input written for the fuzz harnesses). Not a whole number naming a light: refused.
TEST(SceneLoaderHostile, LightIndexThatIsNoLightIsRefused) {
  SceneCopy copy("sphere", "light_index");
  json* light_node = nullptr;
  for (json& node : copy.doc["nodes"])
    if (node.contains("extensions") && node["extensions"].contains("KHR_lights_punctual")) light_node = &node;
  ASSERT_NE(light_node, nullptr) << "the sphere scene has a light";
  json& index = (*light_node)["extensions"]["KHR_lights_punctual"]["light"];
  const std::pair<json, std::string> cases[] = {
      {1e300, "light index 1e+300 does not exist"}, {-1e300, "light index -1e+300 does not exist"},
      {4294967296.0, "light index 4.29497e+09 does not exist"}, {0.5, "light index 0.5 does not exist"},
      {1, "light index 1 does not exist"}, {-1, "light index -1 does not exist"},
      {"0", "light index (not a number) does not exist"},
  };
  for (const auto& [value, phrase] : cases) {
    index = value;
    copy.save_json();
    expect_scene_error(copy.gltf, "KHR_lights_punctual " + phrase);
  }
  index = 0.0;  // a whole number written as a real is still light 0
  copy.save_json();
  EXPECT_EQ(kit::load_scene(copy.gltf.string()).lights.size(), 1u);
}

// The sphere scene's light made a KHR_lights_punctual "directional" light on a
// rotated node under a rotated, non-uniformly scaled parent, with its light, node
// and parent node returned for a test to change.
struct DirectionalCopy {
  SceneCopy copy;
  json* light = nullptr;
  std::string node_name;
  explicit DirectionalCopy(const std::string& case_name) : copy("sphere", case_name) {
    light = &copy.doc["extensions"]["KHR_lights_punctual"]["lights"][0];
    (*light)["type"] = "directional";
    size_t node_index = 0;
    for (size_t i = 0; i < copy.doc["nodes"].size(); ++i)
      if (copy.doc["nodes"][i].contains("extensions") && copy.doc["nodes"][i]["extensions"].contains("KHR_lights_punctual"))
        node_index = i;
    json& node = copy.doc["nodes"][node_index];
    node_name = node.value("name", "");
    // 50 degrees about (1, 2, 0.5) / |.|, as glTF's x, y, z, w.
    const glm::dquat own = glm::angleAxis(glm::radians(50.0), glm::normalize(glm::dvec3(1.0, 2.0, 0.5)));
    node["rotation"] = {own.x, own.y, own.z, own.w};
    const glm::dquat parent = glm::angleAxis(glm::radians(110.0), glm::dvec3(0.0, 1.0, 0.0));
    copy.doc["nodes"].push_back({{"name", "sun_parent"},
                                 {"translation", {3.0, -1.0, 2.0}},
                                 {"rotation", {parent.x, parent.y, parent.z, parent.w}},
                                 {"scale", {2.0, 0.5, 1.5}},
                                 {"children", {node_index}}});
    for (json& root : copy.doc["scenes"][0]["nodes"])
      if (root.get<size_t>() == node_index) root = copy.doc["nodes"].size() - 1;
  }
};

// A directional light is lit (it was dropped before): its direction is its node's
// world -Z, computed here in double through the whole node tree; its intensity is
// the file's (lux) and its range, which glTF says does not apply, is left out.
TEST(SceneLoaderValid, DirectionalLightGetsItsNodesWorldDirection) {
  DirectionalCopy sun("directional_rotated");
  (*sun.light)["intensity"] = 3.25;
  (*sun.light)["color"] = {1.0, 0.8, 0.6};
  (*sun.light)["range"] = 7.0;
  sun.copy.save_json();
  const kit::Scene scene = kit::load_scene(sun.copy.gltf.string());
  ASSERT_EQ(scene.lights.size(), 1u);
  const kit::Light& l = scene.lights[0];
  EXPECT_EQ(l.type, KIT_LIGHT_DIRECTIONAL);
  const glm::dmat4 world = world_matrices(sun.copy.doc).at(sun.node_name);
  const glm::dvec3 expected = glm::normalize(glm::dvec3(world * glm::dvec4(0.0, 0.0, -1.0, 0.0)));
  EXPECT_GT(glm::distance(expected, glm::dvec3(0.0, 0.0, -1.0)), 0.5) << "the rotations must move -Z";
  EXPECT_NEAR(glm::distance(glm::dvec3(l.direction), expected), 0.0, kUnitTolerance);
  EXPECT_NEAR(glm::length(glm::dvec3(l.direction)), 1.0, kUnitTolerance);
  EXPECT_NEAR(l.intensity, 3.25, 1e-6);
  EXPECT_NEAR(glm::distance(glm::dvec3(l.color), glm::dvec3(1.0, 0.8, 0.6)), 0.0, 1e-6);
  EXPECT_EQ(l.range, 0.0f) << "range does not apply to a directional light";
}

// A directional light's values are checked as a point or spot light's are, and
// a node scaled to nothing gives it no direction.
TEST(SceneLoaderErrors, InvalidDirectionalLightIsRefused) {
  {
    DirectionalCopy sun("directional_negative_range");
    (*sun.light)["range"] = -1.0;
    sun.copy.save_json();
    expect_scene_error(sun.copy.gltf, "KHR_lights_punctual light 0 has range -1");
  }
  {
    DirectionalCopy sun("directional_negative_intensity");
    (*sun.light)["intensity"] = -2.0;
    sun.copy.save_json();
    expect_scene_error(sun.copy.gltf, "KHR_lights_punctual light 0 has intensity -2");
  }
  {
    DirectionalCopy sun("directional_zero_scale");
    sun.copy.doc["nodes"].back()["scale"] = {0.0, 0.0, 0.0};
    sun.copy.save_json();
    expect_scene_error(sun.copy.gltf, "KHR_lights_punctual light 0 (directional) is on a node whose transform has no -Z");
  }
  {
    DirectionalCopy sun("light_type_unknown");
    (*sun.light)["type"] = "area";
    sun.copy.save_json();
    expect_scene_error(sun.copy.gltf, "KHR_lights_punctual light 0 has type 'area' (must be point, spot or directional)");
  }
}

// ---- cameras ----

// glTF 2.0's projection matrices ("Projection Matrices") in double, columns first.
glm::dmat4 perspective_projection(double aspect, double yfov, double znear, double zfar) {
  const double t = std::tan(0.5 * yfov);
  glm::dmat4 p(0.0);
  p[0][0] = 1.0 / (aspect * t);
  p[1][1] = 1.0 / t;
  p[2][2] = (zfar + znear) / (znear - zfar);
  p[2][3] = -1.0;
  p[3][2] = 2.0 * zfar * znear / (znear - zfar);
  return p;
}
glm::dmat4 orthographic_projection(double xmag, double ymag, double znear, double zfar) {
  glm::dmat4 p(0.0);
  p[0][0] = 1.0 / xmag;
  p[1][1] = 1.0 / ymag;
  p[2][2] = 2.0 / (znear - zfar);
  p[3][2] = (zfar + znear) / (znear - zfar);
  p[3][3] = 1.0;
  return p;
}

TEST(SceneLoaderCameras, EveryCameraProjectsAsTheSpecSays) {
  SceneCopy copy("sphere", "cameras");
  // The sphere's camera 0 (perspective, no aspectRatio), then one with an aspect
  // ratio and an orthographic one, on nodes after it in the node tree.
  json& cameras = copy.doc["cameras"];
  ASSERT_EQ(cameras.size(), 1u);
  ASSERT_FALSE(cameras[0]["perspective"].contains("aspectRatio"));
  cameras.push_back({{"type", "perspective"}, {"perspective", {{"yfov", 0.7}, {"aspectRatio", 2.0}, {"znear", 0.05}, {"zfar", 50.0}}}});
  cameras.push_back({{"type", "orthographic"}, {"orthographic", {{"xmag", 3.0}, {"ymag", 1.5}, {"znear", 0.0}, {"zfar", 20.0}}}});
  for (int c : {1, 2}) {
    copy.doc["nodes"].push_back({{"name", "camera" + std::to_string(c)}, {"camera", c}, {"translation", {0.0, c, 5.0}}});
    copy.doc["scenes"][0]["nodes"].push_back(copy.doc["nodes"].size() - 1);
  }
  copy.save_json();
  const kit::Scene scene = kit::load_scene(copy.gltf.string());
  ASSERT_EQ(scene.cameras.size(), 3u);
  ASSERT_TRUE(scene.camera.has_value());
  EXPECT_EQ(scene.camera->view, scene.cameras[0].view) << "the first camera stays the default";

  const double window_aspect = 1.5;
  const json& p0 = cameras[0]["perspective"];
  expect_matrix_near(scene.cameras[0].projection(static_cast<float>(window_aspect)),
                     perspective_projection(window_aspect, p0["yfov"], p0["znear"], p0["zfar"]), "camera 0 (window's aspect)");
  expect_matrix_near(scene.cameras[1].projection(static_cast<float>(window_aspect)),
                     perspective_projection(2.0, 0.7, 0.05, 50.0), "camera 1 (its aspectRatio)");
  EXPECT_TRUE(scene.cameras[2].orthographic);
  expect_matrix_near(scene.cameras[2].projection(static_cast<float>(window_aspect)),
                     orthographic_projection(3.0, 1.5, 0.0, 20.0), "camera 2 (orthographic)");
  const std::map<std::string, glm::dmat4> worlds = world_matrices(copy.doc);
  for (int c : {1, 2})
    expect_matrix_near(scene.cameras[static_cast<size_t>(c)].view, glm::inverse(worlds.at("camera" + std::to_string(c))),
                       "camera " + std::to_string(c) + " view");

  // chosen_camera: -1 is the default, N the file's camera N, past the last an error naming the count.
  EXPECT_EQ(kit::chosen_camera(scene, -1).view, scene.cameras[0].view);
  EXPECT_TRUE(kit::chosen_camera(scene, 2).orthographic);
  try {
    kit::chosen_camera(scene, 3);
    ADD_FAILURE() << "camera 3 was chosen";
  } catch (const kit::Error& e) {
    EXPECT_EQ(std::string(e.what()), copy.gltf.string() + ": camera 3 does not exist: the file has 3 cameras (0 to 2)");
  }
}

TEST(SceneLoaderCameras, InvalidCamerasAreRefusedByIndex) {
  SceneCopy copy("sphere", "bad_cameras");
  copy.doc["cameras"][0] = {{"type", "orthographic"}, {"orthographic", {{"xmag", 0.0}, {"ymag", 1.0}, {"znear", 0.1}, {"zfar", 10.0}}}};
  copy.save_json();
  expect_scene_error(copy.gltf, "camera 0 ('') has xmag 0");
  copy.doc["cameras"][0]["orthographic"] = {{"xmag", 1.0}, {"ymag", 1.0}, {"znear", 5.0}, {"zfar", 1.0}};
  copy.save_json();
  expect_scene_error(copy.gltf, "must be 0 <= znear < zfar");
  copy.doc["cameras"][0] = {{"type", "perspective"}, {"perspective", {{"yfov", 0.8}, {"znear", 0.1}, {"zfar", 0.05}}}};
  copy.save_json();
  expect_scene_error(copy.gltf, "camera 0 ('') has zfar");
}

}  // namespace
