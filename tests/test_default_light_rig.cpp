// The default light rig (renderer.h): a scene without lights is lit at lit stages
// when RenderSettings ask for it, and the rig scales with the scene, so a unit
// box made 1 cm or 100 m wide renders the same centre pixel.
#include <gtest/gtest.h>

#include <glm/gtc/matrix_transform.hpp>

#include <string>

#include "kit_test.h"
#include "stages.h"
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
