// The default light rig (renderer.h): a scene without lights is lit at lit stages
// when RenderSettings ask for it, and the rig scales with the scene, so a unit
// box made 1 cm or 100 m wide renders the same centre pixel. These render the
// solutions of labs 2 and 3, so they are instructors' tests.
#include <gtest/gtest.h>

#include <glm/gtc/matrix_transform.hpp>

#include <filesystem>
#include <string>

#include "kit_test.h"
#include "kit_test_files.h"
#include "render/stages.h"
#include "tiny_scenes.h"

namespace {

constexpr int kWidth = 64, kHeight = 48;

// A unit box (six quads facing out) scaled by `scale`, white dielectric, no lights.
kit::Scene box_scene(float scale) {
  struct Face {
    glm::vec3 right, up;
  };
  const Face faces[6] = {{{1, 0, 0}, {0, 1, 0}},  {{-1, 0, 0}, {0, 1, 0}}, {{0, 0, -1}, {0, 1, 0}},
                         {{0, 0, 1}, {0, 1, 0}},  {{1, 0, 0}, {0, 0, -1}}, {{1, 0, 0}, {0, 0, 1}}};
  std::vector<kit::Primitive> primitives;
  std::vector<kit::DrawItem> draws;
  for (const Face& f : faces) {
    kit::Primitive quad = kit::test::quad_primitive(f.right, f.up, {1, 1});
    quad.material = 0;
    const glm::vec3 normal = glm::cross(f.right, f.up);
    draws.push_back({static_cast<int>(primitives.size()),
                     glm::scale(glm::mat4(1.0f), glm::vec3(scale)) * glm::translate(glm::mat4(1.0f), 0.5f * normal)});
    primitives.push_back(quad);
  }
  return kit::test::tiny_scene(primitives, {kit::test::plain_material(0.5f)}, draws, {});
}

// The final image's centre pixel of `stage` (the reference solutions) from the framing camera.
glm::vec4 centre_pixel(const kit::Scene& scene, const std::string& stage_name, bool default_rig) {
  kit::test::context();
  const kit::Stage& stage = kit::find_stage(stage_name);
  kit::RenderSettings settings;
  settings.width = kWidth;
  settings.height = kHeight;
  settings.default_light_rig = default_rig;
  kit::Renderer renderer(stage, kit::stage_library(stage, kit::kit_root() / "solutions"), scene, settings);
  renderer.render(kit::frame_camera(kit::framing_camera(scene), float(kWidth) / float(kHeight)));
  const kit::Image image = renderer.read_view(kit::View::Final, false);
  return {image.at(kWidth / 2, kHeight / 2, 0), image.at(kWidth / 2, kHeight / 2, 1), image.at(kWidth / 2, kHeight / 2, 2),
          image.at(kWidth / 2, kHeight / 2, 3)};
}

// kit-render with an OBJ that brings no lights: the default rig lights it and says
// so; --no-default-lights leaves it dark; --look-at places the camera.
TEST(DefaultLightRig, KitRenderLightsAnObjWithoutLights) {
  const std::filesystem::path dir = kit::test::temp_dir("default_light_rig/kit_render");
  // Two triangles facing +Z, without normals (flat ones are made) or a texture.
  kit::test::write_file(dir / "square.obj", "mtllib square.mtl\nusemtl grey\n"
                                           "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nf 1 2 3\nf 1 3 4\n");
  kit::test::write_file(dir / "square.mtl", "newmtl grey\nKd 0.8 0.8 0.8\nKs 0.04 0.04 0.04\nNs 20\n");
  const std::string base = "'" + kit::test::tool("kit-render") + "' --solution --stage attenuation --size 64x48 --scene '" +
                           (dir / "square.obj").string() + "' --look-at 0,0,3,0,0,0,45 --out ";
  std::string output;
  ASSERT_EQ(kit::test::run(base + "'" + (dir / "lit.png").string() + "'", &output), 0) << output;
  EXPECT_NE(output.find("kit-render: note: scene has no lights: using the default rig (3 point lights"), std::string::npos)
      << output;
  const kit::Image lit = kit::read_image((dir / "lit.png").string());
  EXPECT_GT(lit.at(32, 24, 0), 0.1f) << "the square fills the centre and the rig lights it";

  ASSERT_EQ(kit::test::run(base + "'" + (dir / "dark.png").string() + "' --no-default-lights", &output), 0) << output;
  EXPECT_EQ(output.find("default rig"), std::string::npos) << output;
  const kit::Image dark = kit::read_image((dir / "dark.png").string());
  EXPECT_EQ(dark.at(32, 24, 0) + dark.at(32, 24, 1) + dark.at(32, 24, 2), 0.0f);
}

}  // namespace

TEST(DefaultLightRig, OnlyForScenesWithoutLightsWhenAskedFor) {
  kit::RenderSettings settings;
  const kit::Scene box = box_scene(1.0f);
  EXPECT_FALSE(kit::uses_default_light_rig(box, settings)) << "off unless a tool turns it on";
  settings.default_light_rig = true;
  EXPECT_TRUE(kit::uses_default_light_rig(box, settings));
  EXPECT_EQ(kit::frame_lights(box, kit::find_stage("attenuation"), settings).size(), 3u);
  kit::Scene lit = box;
  lit.lights.push_back(kit::test::point_light({0, 2, 0}, 10.0f));
  EXPECT_FALSE(kit::uses_default_light_rig(lit, settings));
  EXPECT_EQ(kit::frame_lights(lit, kit::find_stage("attenuation"), settings).size(), 1u);
}

TEST(DefaultLightRig, IntensityFollowsTheStagesFalloff) {
  const kit::Scene box = box_scene(100.0f);
  const auto no_falloff = kit::default_light_rig(box, kit::find_stage("lighting"), 0);
  const auto physical = kit::default_light_rig(box, kit::find_stage("attenuation"), 0);
  const auto simple = kit::default_light_rig(box, kit::find_stage("attenuation"), 1);
  ASSERT_EQ(physical.size(), 3u);
  const glm::dvec3 center(0.0);
  for (size_t i = 0; i < physical.size(); ++i) {
    const double d2 = glm::dot(glm::dvec3(physical[i].position) - center, glm::dvec3(physical[i].position) - center);
    EXPECT_NEAR(physical[i].intensity / d2, no_falloff[i].intensity, 1e-5 * no_falloff[i].intensity);
    EXPECT_NEAR(simple[i].intensity / (1.0 + d2), no_falloff[i].intensity, 1e-5 * no_falloff[i].intensity);
  }
}

TEST(DefaultLightRig, SameImageForACentimetreAndAHundredMetreBox) {
  const kit::Scene small = box_scene(0.01f), large = box_scene(100.0f);
  for (const char* stage : {"lighting", "attenuation"}) {
    const glm::vec4 a = centre_pixel(small, stage, true), b = centre_pixel(large, stage, true);
    EXPECT_GT(a.r + a.g + a.b, 0.1f) << stage << ": the rig lights the box";
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(a[c], b[c], 1.0 / 255.0) << stage << " channel " << c;
  }
  // Turned off, the box stays unlit (black: its material emits nothing).
  const glm::vec4 dark = centre_pixel(small, "attenuation", false);
  EXPECT_EQ(dark.r + dark.g + dark.b, 0.0f);
}
