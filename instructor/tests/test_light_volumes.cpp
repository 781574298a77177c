// Lab 7, light volumes (handouts/07-lightvolumes.md): the solution's image against the
// CPU reference in double precision on the grader's three scenes, with the witness that
// the naive state (front faces drawn) loses the light whose volume holds the camera; the
// cut-off's bound against numbers worked out by hand; the work counts against counts
// made without an occlusion query; and the state pragma's errors.
#include <cmath>
#include <cstdio>

#include "reference_frames.h"
#include "render/light_volumes.h"
#include "shader_variants.h"

namespace kit::test {
namespace {

namespace ref = kit::reference;

// Stage 7 with bloom off: its hard bright-pass threshold turns a half-float step of one
// pixel into a blurred blob, which says nothing about the volumes.
RenderSettings volume_settings() {
  RenderSettings s = small_settings();
  s.postprocess = false;
  s.count_light_volume_work = true;
  return s;
}

// Each light's volume adds its term to the RGBA16F target on its own, a rounding the
// reference's single storage step does not model: pixels outside kHdrRelativeTolerance
// must then be within one 8-bit step once displayed (compare_with_reference's rule).
void expect_matches_reference(const std::string& scene_name, Renderer& renderer, const Scene& s) {
  const Frame frame = render_frame(renderer, scene_frame_camera(s, renderer.settings()));
  const ref::ShadingSettings settings = ref::shading_settings(renderer.settings(), renderer.stage().number);
  const PixelList pixels = covered_pixels(frame);
  const Agreement all = compare_with_reference(frame, ref::frame_lights(s, renderer.settings()), settings, pixels);
  std::printf("[ reference ] %s, stage lightvolumes: %s\n", scene_name.c_str(), describe(all).c_str());
  EXPECT_GE(pixels.size(), 1000u) << scene_name;
  EXPECT_EQ(all.failures, 0u) << scene_name << ": " << describe(all);
}

TEST(LightVolumes, SolutionMatchesTheReferenceOnTheGradersScenes) {
  for (const char* name : {"lights", "inside", "range"}) {
    const Scene& s = scene(name);
    auto renderer = make_renderer("lightvolumes", s, volume_settings());
    expect_matches_reference(name, *renderer, s);
  }
}

// The camera inside the first light's volume: drawn with its front faces (back faces
// culled, as opaque geometry is), the volume is behind the camera and its light is gone
// from most of the image; the kit's state (front faces culled) keeps it.
TEST(LightVolumes, FrontFacesLoseTheLightAroundTheCamera) {
  const Scene& s = scene("inside");
  const FrameCamera camera = scene_frame_camera(s, volume_settings());
  const Light& around = s.lights.front();
  ASSERT_LT(glm::distance(camera.position, around.position), around.range) << "the camera must be inside its volume";
  auto kit = make_renderer("lightvolumes", s, volume_settings());
  const std::filesystem::path naive_root = variant_root(
      "light_volumes_front_faces",
      {{"07-lightvolumes/light_volume.vert", "cull(front) depth(greater_equal)", "cull(back) depth(less_equal)"}});
  auto naive = make_renderer("lightvolumes", s, volume_settings(),
                             full_root_library(find_stage("lightvolumes"), naive_root));
  const Frame kept = render_frame(*kit, camera);
  const Frame lost = render_frame(*naive, camera);
  const ref::ShadingSettings settings = ref::shading_settings(kit->settings(), kit->stage().number);
  const PixelList pixels = covered_pixels(kept);
  const std::vector<Light> lights = ref::frame_lights(s, kit->settings());
  const Agreement kit_agreement = compare_with_reference(kept, lights, settings, pixels);
  const Agreement naive_agreement = compare_with_reference(lost, lights, settings, pixels);
  std::printf("[ reference ] inside: back faces %s; front faces %s\n", describe(kit_agreement).c_str(),
              describe(naive_agreement).c_str());
  EXPECT_EQ(kit_agreement.failures, 0u);
  EXPECT_GT(naive_agreement.failures, pixels.size() / 2);
  EXPECT_EQ(naive->light_volume_state().cull, LightVolumeState::Cull::Back);
}

// The budget is the radiance whose display is one 8-bit step at black: (1/255)^2.2 is
// 5.07705e-6 (worked out by hand: ln(1/255) = -5.54126, times 2.2 = -12.19078, and
// e^-12.19078 = 5.07705e-6), so q / (1 - q) = 5.07708e-6; and
// Reinhard's L / (1 + L) of the budget gives it back. At gamma 1 the step is 1/255.
// The radius of a white 1 cd point light at epsilon 1/pi is 1 m: I / (pi r^2) = epsilon.
TEST(LightVolumes, CutoffBoundAgainstNumbersWorkedByHand) {
  EXPECT_NEAR(light_volume_budget(2.2f), 5.07708e-6, 1e-10);
  const double budget = light_volume_budget(2.2f);
  EXPECT_NEAR(std::pow(budget / (1.0 + budget), 1.0 / 2.2), 1.0 / 255.0, 1e-9);
  EXPECT_NEAR(light_volume_budget(1.0f), (1.0 / 255.0) / (1.0 - 1.0 / 255.0), 1e-9);
  Light white;
  white.type = KIT_LIGHT_POINT;
  white.intensity = 1.0f;
  EXPECT_NEAR(light_cutoff_radius(white, 1.0f / 3.14159265f, 0), 1.0f, 1e-5f);
  EXPECT_NEAR(light_cutoff_radius(white, 1.0f / 3.14159265f, 1), 0.0f, 1e-3f) << "simple model: 1 / (1 + r^2)";
  white.range = 0.4f;
  EXPECT_FLOAT_EQ(light_cutoff_radius(white, 1.0f / 3.14159265f, 0), 0.4f) << "a range is exact: the smaller bound";
  // Two lights without a range share the budget; a ranged one takes none of it.
  Light ranged = white, free = white;
  free.range = 0.0f;
  EXPECT_FLOAT_EQ(light_volume_epsilon({free, free, ranged}, 2.2f), light_volume_budget(2.2f) / 2.0f);
  // At the radius, the reference's diffuse term of a white Lambertian surface facing the
  // light is the light's share of the budget: what the bound promises.
  const float epsilon = light_volume_epsilon({free}, 2.2f);
  const double r = light_cutoff_radius(free, epsilon, 0);
  EXPECT_NEAR(free.intensity / (r * r) / ref::KIT_PI, epsilon, 1e-3 * epsilon);
}

// The counts: every pixel once where the camera sits inside every volume, the surface
// pixels as the G-buffer's coverage mask says, and each light's sphere no more than its
// bounding square on screen.
TEST(LightVolumes, WorkCountsAgreeWithCountsMadeOnTheCpu) {
  const Scene& s = scene("inside");
  auto renderer = make_renderer("lightvolumes", s, volume_settings());
  const Frame frame = render_frame(*renderer, scene_frame_camera(s, renderer->settings()));
  const LightVolumeWork& work = renderer->light_volume_work();
  EXPECT_EQ(work.volume_lights, 2);
  EXPECT_EQ(work.surface_pixels, covered_pixels(frame).size());
  const uint64_t pixels = static_cast<uint64_t>(kSmallWidth) * kSmallHeight;
  // The first light's volume holds the camera: it covers the whole screen, once.
  EXPECT_GT(work.volume_coverage, pixels);
  EXPECT_LT(work.volume_coverage, 2 * pixels);
  EXPECT_LE(work.shaded_fragments, work.volume_coverage);
  EXPECT_GT(work.shaded_fragments, pixels / 2);
}

// The evidence that names what is wrong with a student's volumes (VolumeEvidence), light by
// light on the "inside" scene (two lights, the camera inside the first's volume). The
// surface pixels each light must shade are counted again here on the CPU from the G-buffer's
// positions; the solution's volumes miss and add nothing and its state shades each of those
// pixels once. Witnesses: a volume of half the radius leaves out most of the sphere's pixels,
// and drawing both faces without a depth test shades the second light's pixels twice; each
// is seen by its own measure and not by the other.
TEST(LightVolumes, EvidenceSaysWhichPartOfTheVolumesIsWrong) {
  const Scene& s = scene("inside");
  const FrameCamera camera = scene_frame_camera(s, volume_settings());
  auto evidence = [&](const std::vector<LineSwap>& swaps, const char* name) {
    auto renderer = swaps.empty() ? make_renderer("lightvolumes", s, volume_settings())
                                  : make_renderer("lightvolumes", s, volume_settings(),
                                                  full_root_library(find_stage("lightvolumes"), variant_root(name, swaps)));
    const Frame frame = render_frame(*renderer, camera);
    return std::make_pair(renderer->light_volume_work().evidence, frame);
  };
  const auto [right, frame] = evidence({}, "");
  ASSERT_EQ(right.lights, 2);
  EXPECT_GT(right.footprint, 0u);
  EXPECT_EQ(right.missing, 0u);
  EXPECT_EQ(right.extra, 0u);
  EXPECT_EQ(right.shaded_wrong, 0u);
  EXPECT_TRUE(right.adds);
  EXPECT_EQ(right.worst_volume_light, -1);
  EXPECT_EQ(right.worst_state_light, -1);
  // The pixels to shade, counted on the CPU: a surface within a light's volume radius.
  const std::vector<Light> lights = ref::frame_lights(s, volume_settings());
  const float epsilon = light_volume_epsilon(lights, volume_settings().gamma);
  uint64_t must_shade = 0;
  for (const Light& light : lights) {
    if (light.type == KIT_LIGHT_DIRECTIONAL) continue;
    const double r = light_cutoff_radius(light, epsilon, volume_settings().attenuation_model);
    for (const auto& [x, y] : covered_pixels(frame)) {
      const ref::dvec3 p = ref::pixel_rgb(frame.gbuffer.position, x, y);
      must_shade += glm::length(p - ref::dvec3(light.position)) <= r;
    }
  }
  ASSERT_GT(must_shade, 1000u);
  // A pixel exactly at the radius may go either way in float.
  EXPECT_NEAR(static_cast<double>(right.must_shade), static_cast<double>(must_shade), 2.0 + 1e-3 * must_shade);

  const auto [small, small_frame] =
      evidence({{"07-lightvolumes/light_volume.vert", "light.position + light.volume_radius * a_position",
                 "light.position + 0.5 * light.volume_radius * a_position"}},
               "light_volumes_half_radius");
  // The second light's sphere (the first holds the camera at half its radius too): a quarter of it.
  EXPECT_EQ(small.worst_volume_light, 1);  // from 0, as the scene lists its lights
  EXPECT_GT(small.worst_missing, small.worst_footprint / 2) << "half the radius covers about a quarter of the pixels";
  EXPECT_GT(small.missing, 0u);
  EXPECT_EQ(small.extra, 0u);
  EXPECT_EQ(small.shaded_wrong, 0u) << "the state is the solution's";

  const auto [twice, twice_frame] =
      evidence({{"07-lightvolumes/light_volume.vert", "cull(front) depth(greater_equal)", "cull(none) depth(off)"}},
               "light_volumes_both_faces");
  EXPECT_EQ(twice.missing, 0u);
  EXPECT_EQ(twice.extra, 0u);
  // The camera is inside the first light's volume (one face in front of it), outside the second's.
  EXPECT_GT(twice.shaded_wrong, 1000u);
  EXPECT_LT(twice.shaded_wrong, right.must_shade);
  EXPECT_EQ(twice.worst_shaded, 2 * twice.worst_must_shade);
}

TEST(LightVolumes, StatePragmaErrorsNameTheFileAndLine) {
  auto assembled = [](const std::string& text) {
    AssembledShader a;
    a.text = text;
    a.files = {"labs/07-lightvolumes/light_volume.vert"};
    int line = 0;
    for (char c : text)
      if (c == '\n') a.lines.push_back({0, ++line});
    return a;
  };
  const LightVolumeState ok =
      parse_light_volume_state(assembled("#version 330 core\n#pragma kit_light_volume cull(front) depth(off) blend(add)\n"));
  EXPECT_EQ(describe(ok), "cull(front) depth(off) blend(add)");
  auto message = [&](const std::string& text) {
    try {
      parse_light_volume_state(assembled(text));
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message("#version 330 core\nvoid main() {}\n").find("labs/07-lightvolumes/light_volume.vert: no line"),
            std::string::npos);
  const std::string typo = message("#version 330 core\n\n#pragma kit_light_volume cull(front) depth(greater) blend(add)\n");
  EXPECT_NE(typo.find("labs/07-lightvolumes/light_volume.vert:3: 'depth(greater)' is not a light volume setting"),
            std::string::npos) << typo;
  EXPECT_NE(message("#version 330 core\n#pragma kit_light_volume cull(front) blend(add)\n").find("no depth setting"),
            std::string::npos);
}

}  // namespace
}  // namespace kit::test
