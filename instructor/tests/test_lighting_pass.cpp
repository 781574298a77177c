// The framework's levers on the lighting pass's speed (handouts/02-lighting.md, "Speed")
// change no pixel: the light type, range and attenuation model compiled in as constants
// when a frame allows it, and the background skipped by the depth test from stage 3 on.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "base/error.h"
#include "kit_test.h"
#include "shader_variants.h"
#include "render/stages.h"
#include "tiny_scenes.h"

namespace {

using kit::Light;

constexpr int kWidth = kit::test::kSmallWidth;
constexpr int kHeight = kit::test::kSmallHeight;

// kit::test::small_settings with lab 3's falloff model `attenuation_model`.
kit::RenderSettings settings_with_model(int attenuation_model) {
  kit::RenderSettings s = kit::test::small_settings();
  s.attenuation_model = attenuation_model;
  return s;
}

kit::Image render_hdr(const kit::Stage& stage, kit::ShaderLibrary library, const kit::Scene& scene,
                      const kit::RenderSettings& settings) {
  kit::test::context();
  kit::Renderer renderer(stage, std::move(library), scene, settings);
  const kit::Camera camera = scene.camera ? *scene.camera : kit::framing_camera(scene);
  renderer.render(kit::frame_camera(camera, static_cast<float>(kWidth) / kHeight));
  return renderer.read_view(kit::View::Hdr, true);
}

kit::Image render_hdr(const std::string& stage_name, const kit::Scene& scene, const kit::RenderSettings& settings) {
  const kit::Stage& stage = kit::find_stage(stage_name);
  return render_hdr(stage, kit::stage_library(stage, kit::kit_root() / "solutions"), scene, settings);
}

Light light_of_type(int type) {
  Light l;
  l.type = type;
  l.position = {0.4f, 1.5f, 0.6f};
  l.direction = glm::normalize(glm::vec3(-0.2f, -1.0f, -0.3f));
  l.intensity = type == KIT_LIGHT_DIRECTIONAL ? 2.0f : 20.0f;
  l.inner_cone = 0.3f;
  l.outer_cone = 0.6f;
  return l;
}

// Largest difference relative to the larger value (absolute below 1e-3).
double max_relative_difference(const kit::Image& a, const kit::Image& b) {
  double worst = 0.0;
  for (size_t i = 0; i < a.pixels.size(); ++i) {
    const double scale = std::max({1e-3, std::abs(double(a.pixels[i])), std::abs(double(b.pixels[i]))});
    worst = std::max(worst, std::abs(double(a.pixels[i]) - double(b.pixels[i])) / scale);
  }
  return worst;
}

TEST(LightingPassConstants, EachFrameGetsTheDefinesItsLightsAllow) {
  kit::test::context();
  struct Case {
    std::vector<int> types;
    float range;
    std::vector<std::string> defined;
  };
  const Case cases[] = {
      {{KIT_LIGHT_POINT, KIT_LIGHT_POINT}, 0.0f, {kit::kLightsAllPoint, kit::kLightsWithoutRange}},
      {{KIT_LIGHT_SPOT}, 0.0f, {kit::kLightsAllSpot, kit::kLightsWithoutRange}},
      {{KIT_LIGHT_DIRECTIONAL}, 0.0f, {kit::kLightsAllDirectional, kit::kLightsWithoutRange}},
      {{KIT_LIGHT_POINT, KIT_LIGHT_SPOT}, 0.0f, {kit::kLightsWithoutRange}},
      {{KIT_LIGHT_POINT}, 5.0f, {kit::kLightsAllPoint}},
      {{}, 0.0f, {kit::kLightsWithoutRange}},
  };
  const std::string all[] = {kit::kLightsInTexture, kit::kLightsAllPoint, kit::kLightsAllSpot,
                             kit::kLightsAllDirectional, kit::kLightsWithoutRange};
  kit::ShaderLibrary library;
  for (const Case& c : cases) {
    std::vector<Light> lights;
    for (int type : c.types) {
      lights.push_back(light_of_type(type));
      lights.back().range = c.range;
    }
    kit::LightBuffers(lights).apply_defines(library);
    for (const std::string& name : all) {
      const bool expected = std::find(c.defined.begin(), c.defined.end(), name) != c.defined.end();
      EXPECT_EQ(library.has_define(name), expected) << name << " with " << c.types.size() << " lights";
    }
  }
  // More lights than the block holds: read from the texture.
  kit::LightBuffers(std::vector<Light>(KIT_LIGHT_BLOCK_CAPACITY + 1, light_of_type(KIT_LIGHT_POINT)))
      .apply_defines(library);
  EXPECT_TRUE(library.has_define(kit::kLightsInTexture));
  kit::apply_attenuation_model_define(library, 0);
  EXPECT_TRUE(library.has_define("KIT_ATTENUATION_MODEL_PHYSICAL"));
  EXPECT_FALSE(library.has_define("KIT_ATTENUATION_MODEL_SIMPLE"));
  kit::apply_attenuation_model_define(library, 1);
  EXPECT_TRUE(library.has_define("KIT_ATTENUATION_MODEL_SIMPLE"));
  EXPECT_FALSE(library.has_define("KIT_ATTENUATION_MODEL_PHYSICAL"));
}

// One light type (and no range) compiled in as constants, against the general code the
// same lights take when a light that adds nothing (black, with a range, of another type)
// joins them: the same HDR image to float rounding, at stages 2 and 3 and under both
// attenuation models.
TEST(LightingPassConstants, ConstantTypeRangeAndModelChangeNoPixel) {
  const kit::Material material = kit::test::plain_material(0.35f);
  for (int type : {KIT_LIGHT_POINT, KIT_LIGHT_SPOT, KIT_LIGHT_DIRECTIONAL}) {
    Light second = light_of_type(type);
    second.position = {-0.7f, 1.2f, -0.4f};
    second.color = {0.3f, 0.6f, 1.0f};
    Light nothing = light_of_type(type == KIT_LIGHT_POINT ? KIT_LIGHT_SPOT : KIT_LIGHT_POINT);
    nothing.color = glm::vec3(0.0f);
    nothing.range = 3.0f;
    const kit::Scene constant = kit::test::floor_scene(material, {light_of_type(type), second});
    const kit::Scene general = kit::test::floor_scene(material, {light_of_type(type), second, nothing});
    for (const char* stage : {"lighting", "attenuation"}) {
      for (int model : {0, 1}) {
        SCOPED_TRACE(std::string(stage) + ", light type " + std::to_string(type) + ", model " + std::to_string(model));
        const kit::Image a = render_hdr(stage, constant, settings_with_model(model));
        const kit::Image b = render_hdr(stage, general, settings_with_model(model));
        double lit = 0.0;
        for (float v : a.pixels) lit = std::max(lit, double(v));
        EXPECT_GT(lit, 0.05) << "the lights reach the floor";
        EXPECT_LE(max_relative_difference(a, b), 2e-3);  // RGBA16F: 1 ulp is 1/1024 relative
      }
    }
  }
}

// A program that fails to build under a new define (here: only under the simple
// attenuation model) fails every frame until it builds, and the frame never falls back to
// the programs built for the old model. Witness: with the rebuild keyed on whether the
// defines changed, the second frame saw nothing to change and drew with the physical
// model's programs.
TEST(LightingPassConstants, AFailedRebuildIsTriedAgainNotSkipped) {
  kit::test::context();
  const kit::Stage& stage = kit::find_stage("attenuation");
  const auto root = kit::test::variant_root(
      "lighting_pass_failed_rebuild",
      {{"03-attenuation/attenuation.glsl", "float spot_cone_factor(Light light, vec3 p) {",
        "#ifdef KIT_ATTENUATION_MODEL_SIMPLE\n#error the simple model does not compile here\n#endif\n"
        "float spot_cone_factor(Light light, vec3 p) {"}});
  const kit::Scene& scene = kit::test::scene("sphere");
  kit::Renderer renderer(stage, kit::test::full_root_library(stage, root), scene, settings_with_model(0));
  const kit::FrameCamera camera =
      kit::frame_camera(scene.camera ? *scene.camera : kit::framing_camera(scene), static_cast<float>(kWidth) / kHeight);
  renderer.render(camera);
  renderer.settings().attenuation_model = 1;
  for (int frame = 0; frame < 2; ++frame) {
    SCOPED_TRACE("frame " + std::to_string(frame));
    try {
      renderer.render(camera);
      ADD_FAILURE() << "rendered with the simple model although its program does not compile";
    } catch (const kit::Error& e) {
      EXPECT_NE(std::string(e.what()).find("the simple model does not compile here"), std::string::npos) << e.what();
    }
  }
  renderer.settings().attenuation_model = 0;
  EXPECT_NO_THROW(renderer.render(camera));
}

// From stage 3 on the lighting pass runs only over surfaces. Witness: a lighting.frag
// whose background branch writes magenta instead of the clear colour. At stage 3 it
// never runs there (every background pixel is the clear colour, every surface pixel
// the solution's, bit for bit); at stage 2, lab 2's own, it runs on every pixel and the
// mistake shows, as it must for the lab's coverage-mask task.
TEST(LightingPassBackground, SkippedByTheDepthTestFromStage3AndOnlyThere) {
  const kit::Scene& scene = kit::test::scene("default");
  const auto root = kit::test::variant_root(
      "lighting_pass_background",
      {{"02-lighting/lighting.frag", "out_color = vec4(u_clear_color, 1.0);", "out_color = vec4(1.0, 0.0, 1.0, 1.0);"}});
  const kit::RenderSettings settings = kit::test::small_settings();
  for (const char* name : {"lighting", "attenuation"}) {
    SCOPED_TRACE(name);
    const kit::Stage& stage = kit::find_stage(name);
    EXPECT_EQ(kit::skips_background_pixels(stage), stage.number > 2);
    const kit::Image solution = render_hdr(name, scene, settings);
    const kit::Image variant = render_hdr(stage, kit::test::full_root_library(stage, root), scene, settings);
    auto renderer = kit::test::render_stage(name, "default", settings);
    const kit::Image material = renderer->read_view(kit::View::Material, true);
    int background = 0, magenta = 0, surface_differs = 0;
    for (int y = 0; y < kHeight; ++y) {
      for (int x = 0; x < kWidth; ++x) {
        const bool covered = material.at(x, y, 3) >= 0.5f;
        bool same = true;
        for (int c = 0; c < 3; ++c) same = same && variant.at(x, y, c) == solution.at(x, y, c);
        if (covered) {
          surface_differs += !same;
          continue;
        }
        ++background;
        magenta += variant.at(x, y, 0) == 1.0f && variant.at(x, y, 1) == 0.0f && variant.at(x, y, 2) == 1.0f;
        for (int c = 0; c < 3; ++c)
          EXPECT_NEAR(solution.at(x, y, c), settings.clear_color[c], 1e-3) << "background pixel " << x << "," << y;
      }
    }
    ASSERT_GT(background, kWidth * kHeight / 10) << "the default scene shows background";
    EXPECT_EQ(surface_differs, 0);
    EXPECT_EQ(magenta, stage.number > 2 ? 0 : background);
  }
}

}  // namespace
