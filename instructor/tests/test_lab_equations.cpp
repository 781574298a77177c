// Lab 2 and lab 3 output against a CPU double-precision evaluation of the same
// equations (instructor/reference/cpu_reference.h) on the SAME read-back G-buffer: every
// covered pixel of the default, grazing, sphere, sun and range scenes plus a close-up of the
// sphere's silhouette, at stage lighting and at stage attenuation with both
// falloff models and gamma 2.2 and 1.0. A pixel agrees when its linear HDR value
// is within 1e-3 relative (measured from the fp16 values either side of the
// reference) or its displayed value within 1/255. A copy of lab 2 with a wrong BRDF must fail the same check.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <regex>
#include <string>
#include <vector>

#include "cpu_reference.h"
#include "gbuffer_layout.h"
#include "kit_test.h"
#include "kit_test_files.h"
#include "reference_frames.h"
#include "shader_variants.h"

namespace kit::test {
namespace {

namespace ref = kit::reference;

// Pixels seen this close to edge-on count as grazing (the issue: n.v < 0.05).
constexpr double kGrazingNDotV = 0.05;
// Every frame compares at least this many covered pixels (the issue's sample size).
constexpr size_t kMinPixelsPerFrame = 1000;
// Grazing pixels each grazing view must contain, so the grazing claim is tested.
constexpr size_t kMinGrazingPixels = 100;
// Share of each frame's pixels that must agree in linear HDR itself, not only once
// displayed. The displayed bound is there for the few ill-conditioned pixels: at the
// GGX peak of a near-mirror surface d = (n.h)^2 (alpha^2 - 1) + 1 cancels to ~alpha^2
// in float, and D's relative error grows past 1e-3 where the display saturates.
constexpr double kMinHdrAgreement = 0.99;

// One stage configuration the scenes are rendered in.
struct Config {
  const char* stage;
  int attenuation_model;
  float gamma;
};
// Stage lighting displays through a clamp, so gamma and the falloff model do not
// reach it: one configuration. Stage attenuation: both models, both gammas.
const Config kConfigs[] = {
    {"lighting", 0, 2.2f},   {"attenuation", 0, 2.2f}, {"attenuation", 0, 1.0f},
    {"attenuation", 1, 2.2f}, {"attenuation", 1, 1.0f},
};

struct CameraView {
  std::string name;
  FrameCamera camera;
  bool grazing;  // must contain kMinGrazingPixels grazing pixels
};

// Renders `scene_name` from every view in every configuration and checks each
// frame against the reference. Prints one line per frame for the record.
void check_scene(const std::string& scene_name, const Scene& s, const std::vector<CameraView>& views) {
  std::unique_ptr<Renderer> renderer;
  std::string current_stage;
  for (const Config& config : kConfigs) {
    if (current_stage != config.stage) {
      renderer = make_renderer(config.stage, s, small_settings());
      current_stage = config.stage;
    }
    renderer->settings().attenuation_model = config.attenuation_model;
    renderer->settings().gamma = config.gamma;
    const ref::ShadingSettings settings = ref::shading_settings(renderer->settings(), renderer->stage().number);
    const std::vector<Light> lights = ref::frame_lights(s, renderer->settings());
    for (const CameraView& view : views) {
      const Frame frame = render_frame(*renderer, view.camera);
      const PixelList pixels = covered_pixels(frame);
      const PixelList grazing = grazing_pixels(frame, kGrazingNDotV);
      const Agreement all = compare_with_reference(frame, lights, settings, pixels);
      const Agreement edge = compare_with_reference(frame, lights, settings, grazing);
      char configuration[64];
      std::snprintf(configuration, sizeof configuration, " stage %s, model %d, gamma %.1f", config.stage,
                    config.attenuation_model, config.gamma);
      const std::string label = scene_name + "/" + view.name + configuration;
      std::printf("[ reference ] %s: %s\n", label.c_str(), describe(all).c_str());
      std::printf("[ reference ] %s grazing (n.v < %.2f): %s\n", label.c_str(), kGrazingNDotV, describe(edge).c_str());
      EXPECT_GE(pixels.size(), kMinPixelsPerFrame) << label;
      if (view.grazing) {
        EXPECT_GE(grazing.size(), kMinGrazingPixels) << label;
      }
      EXPECT_EQ(all.failures, 0u) << label << ": " << describe(all);
      EXPECT_GE(static_cast<double>(all.hdr_within), kMinHdrAgreement * static_cast<double>(all.pixels)) << label;
    }
  }
}

// --- The reference's own ingredients -------------------------------------------------

// Every constant the reference mirrors still has the value the shader text gives it.
TEST(LabEquations, MirroredConstantsMatchShaderText) {
  const std::regex number(R"([-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?)");
  for (const ref::MirroredConstant& constant : ref::mirrored_constants()) {
    const std::string text = read_file(kit_root() / constant.file);
    const std::regex declaration("const\\s+[a-z0-9\\[\\]]+\\s+" + std::string(constant.name) + "(\\[\\d+\\])?\\s*=\\s*([^;]*);");
    std::smatch match;
    ASSERT_TRUE(std::regex_search(text, match, declaration)) << constant.name << " is not declared in " << constant.file;
    std::string rhs = match[2];
    // Values of a vector or array follow its constructor's parenthesis (vec3(, float[]().
    if (size_t open = rhs.find('('); open != std::string::npos) rhs = rhs.substr(open + 1);
    std::vector<double> values;
    for (auto it = std::sregex_iterator(rhs.begin(), rhs.end(), number); it != std::sregex_iterator(); ++it)
      values.push_back(std::stod(it->str()));
    ASSERT_EQ(values.size(), constant.values.size()) << constant.name;
    for (size_t i = 0; i < values.size(); ++i)
      EXPECT_NEAR(values[i], constant.values[i], 1e-12 * std::fabs(constant.values[i])) << constant.name << "[" << i << "]";
  }
}

// The flux the renderer uploads (float) is the double formula's, and the
// reference's uploaded_light reproduces the upload exactly.
TEST(LabEquations, LightFluxMatchesRenderer) {
  Light point;
  point.intensity = 50.0f;
  Light spot;
  spot.type = KIT_LIGHT_SPOT;
  spot.intensity = 80.0f;
  spot.inner_cone = 0.25f;
  spot.outer_cone = 0.45f;
  Light sun;
  sun.type = KIT_LIGHT_DIRECTIONAL;
  sun.intensity = 3.0f;
  EXPECT_EQ(kit::light_flux(sun), 0.0f) << "a directional light has no finite flux";
  EXPECT_EQ(ref::exact_light_flux(sun), 0.0);
  for (const Light& l : {point, spot}) {
    const double exact = ref::exact_light_flux(l);
    // float evaluation of a handful of operations: a few float epsilons.
    EXPECT_NEAR(kit::light_flux(l), exact, 1e-6 * exact);
    EXPECT_EQ(ref::uploaded_light(l).flux, static_cast<double>(kit::light_flux(l)));
  }
  EXPECT_NEAR(ref::exact_light_flux(point), 4.0 * ref::KIT_PI * 50.0, 1e-12);
  // Spot normalisation from the seed: 2 pi (1 - (cos umbra + cos penumbra) / 2) I.
  EXPECT_NEAR(ref::exact_light_flux(spot), 2.0 * ref::KIT_PI * (1.0 - 0.5 * (std::cos(double{0.25f}) + std::cos(double{0.45f}))) * 80.0,
              1e-9);
}

// fp16 rounding and bracketing as the HDR target stores values: ties, subnormals, overflow.
TEST(LabEquations, HalfRounding) {
  EXPECT_EQ(ref::round_to_half(1.0 + std::ldexp(1.0, -11)), 1.0);  // tie: to even (1.0)
  EXPECT_EQ(ref::round_to_half(1.0 + 3 * std::ldexp(1.0, -11)), 1.0 + std::ldexp(1.0, -9));  // tie: up to even
  EXPECT_EQ(ref::round_to_half(1.0 + std::ldexp(1.0, -10)), 1.0 + std::ldexp(1.0, -10));  // representable
  EXPECT_EQ(ref::round_to_half(-3.0e-8), -std::ldexp(1.0, -24));                           // subnormal step 2^-24
  EXPECT_EQ(ref::round_to_half(65504.0), 65504.0);
  EXPECT_EQ(ref::round_to_half(65519.0), 65504.0);
  EXPECT_TRUE(std::isinf(ref::round_to_half(65520.0)));
  const ref::HalfNeighbours tie = ref::half_neighbours(1.0 + std::ldexp(1.0, -11));
  EXPECT_EQ(tie.below, 1.0);
  EXPECT_EQ(tie.above, 1.0 + std::ldexp(1.0, -10));
  EXPECT_EQ(ref::half_neighbours(0.5).below, 0.5);
  EXPECT_EQ(ref::half_neighbours(0.5).above, 0.5);
  EXPECT_EQ(ref::half_neighbours(-3.0e-8).below, -std::ldexp(1.0, -24));
  EXPECT_EQ(ref::half_neighbours(65510.0).below, 65504.0);
  EXPECT_TRUE(std::isinf(ref::half_neighbours(65510.0).above));
}

// --- GPU against reference ------------------------------------------------------------

TEST(LabEquations, DefaultSceneMatchesReference) {
  const Scene& s = scene("default");
  check_scene("default", s, {{"camera", scene_frame_camera(s, small_settings()), false}});
}

// glTF ranges short enough that the window (lights.glsl kit_range_window) dims and
// cuts off the lights across the visible floor: stage 3's falloff with the window.
TEST(LabEquations, DefaultSceneWithLightRangesMatchesReference) {
  constexpr float kPointRange = 3.0f, kSpotRange = 8.0f;  // metres: the spot stands 7 m from the shapes
  Scene s = scene("default");
  for (Light& light : s.lights) light.range = light.type == KIT_LIGHT_SPOT ? kSpotRange : kPointRange;
  const FrameCamera camera = scene_frame_camera(s, small_settings());
  check_scene("default-ranged", s, {{"camera", camera, false}});

  // The check means something only if the window varies over the image: some
  // covered pixels lie past every point light's range and some inside one but
  // dimmed (0 < window < 1).
  std::unique_ptr<Renderer> renderer = make_renderer("attenuation", s, small_settings());
  const Frame frame = render_frame(*renderer, camera);
  size_t beyond_all = 0, dimmed = 0;
  for (const auto& [x, y] : covered_pixels(frame)) {
    const ref::dvec3 p = ref::gbuffer_sample(frame.gbuffer, x, y).position;
    bool inside_any = false, partly = false;
    for (const Light& light : s.lights) {
      if (light.type != KIT_LIGHT_POINT) continue;
      const double q = glm::distance(p, ref::dvec3(light.position)) / light.range;
      inside_any |= q < 1.0;
      partly |= q > 0.5 && q < 1.0;
    }
    beyond_all += !inside_any;
    dimmed += partly;
  }
  EXPECT_GT(beyond_all, kMinPixelsPerFrame / 10);
  EXPECT_GT(dimmed, kMinPixelsPerFrame / 10);
}

// The plane runs to the horizon: its far rows are seen and lit at grazing angles.
TEST(LabEquations, GrazingSceneMatchesReference) {
  const Scene& s = scene("grazing");
  check_scene("grazing", s, {{"camera", scene_frame_camera(s, small_settings()), true}});
}

// The scene camera, and a close-up of the outline (sphere_silhouette_camera).
TEST(LabEquations, SphereSceneMatchesReference) {
  const Scene& s = scene("sphere");
  check_scene("sphere", s, {{"camera", scene_frame_camera(s, small_settings()), false},
                         {"silhouette", sphere_silhouette_camera(s, small_settings()), true}});
}

// A low sun (a directional light, l = -direction, no falloff) and a point light
// over a floor and a sphere (tools/scenes/scene_catalogue.cpp build_sun_scene).
TEST(LabEquations, SunSceneMatchesReference) {
  const Scene& s = scene("sun");
  ASSERT_EQ(std::count_if(s.lights.begin(), s.lights.end(), [](const Light& l) { return l.type == KIT_LIGHT_DIRECTIONAL; }), 1);
  check_scene("sun", s, {{"camera", scene_frame_camera(s, small_settings()), false}});
}

// Witness for the sun scene: the naive path, the sun evaluated as a point light at
// its node's position (what a lighting pass reading light.position for every light
// computes), is far outside the tolerance on the very frames the kit's solutions
// pass, at stage 2 (l alone) and at stage 3 (l and the falloff).
TEST(LabEquations, SunAsPointLightAtItsNodeFailsTheCheck) {
  const Scene& s = scene("sun");
  const FrameCamera camera = scene_frame_camera(s, small_settings());
  for (const char* stage : {"lighting", "attenuation"}) {
    auto renderer = make_renderer(stage, s, small_settings());
    const ref::ShadingSettings settings = ref::shading_settings(renderer->settings(), renderer->stage().number);
    const std::vector<Light> lights = ref::frame_lights(s, renderer->settings());
    std::vector<Light> naive = lights;
    for (Light& light : naive)
      if (light.type == KIT_LIGHT_DIRECTIONAL) light.type = KIT_LIGHT_POINT;
    ASSERT_NE(naive.size(), 0u);
    const Frame frame = render_frame(*renderer, camera);
    const PixelList pixels = covered_pixels(frame);
    const Agreement kit = compare_with_reference(frame, lights, settings, pixels);
    const Agreement point = compare_with_reference(frame, naive, settings, pixels);
    std::printf("[ reference ] sun, stage %s: directional %s; as a point light at its node %s\n", stage,
                describe(kit).c_str(), describe(point).c_str());
    EXPECT_EQ(kit.failures, 0u) << stage << ": " << describe(kit);
    EXPECT_GT(point.failures, pixels.size() / 2) << stage << ": " << describe(point);
    EXPECT_GT(point.max_hdr_relative, 100.0 * kHdrRelativeTolerance) << stage;
  }
}

// kit-grade's range scene (a point and a spot light whose glTF range ends in view) against
// the reference, and its witness: the same frames evaluated with the ranges dropped (what
// a falloff without kit_range_window computes) fail on much of the floor, at stage 3,
// where the window applies.
TEST(LabEquations, RangeSceneMatchesReferenceAndNoWindowFails) {
  const Scene& s = scene("range");
  ASSERT_EQ(std::count_if(s.lights.begin(), s.lights.end(), [](const Light& l) { return l.range > 0.0f; }), 2);
  check_scene("range", s, {{"camera", scene_frame_camera(s, small_settings()), false}});
  auto renderer = make_renderer("attenuation", s, small_settings());
  const ref::ShadingSettings settings = ref::shading_settings(renderer->settings(), renderer->stage().number);
  const std::vector<Light> lights = ref::frame_lights(s, renderer->settings());
  std::vector<Light> unlimited = lights;
  for (Light& light : unlimited) light.range = 0.0f;
  const Frame frame = render_frame(*renderer, scene_frame_camera(s, small_settings()));
  const PixelList pixels = covered_pixels(frame);
  const Agreement kit = compare_with_reference(frame, lights, settings, pixels);
  const Agreement no_window = compare_with_reference(frame, unlimited, settings, pixels);
  std::printf("[ reference ] range, stage attenuation: with the window %s; without it %s\n", describe(kit).c_str(),
              describe(no_window).c_str());
  EXPECT_EQ(kit.failures, 0u) << describe(kit);
  EXPECT_GT(no_window.failures, pixels.size() / 4) << describe(no_window);
}

// The reference's analytic surfaces (camera rays against the sphere and the plane)
// land where the rasterised G-buffer says: same coverage, positions within the
// mesh's tessellation and fp16 storage, normals and materials alike.
TEST(LabEquations, AnalyticSurfacesMatchTheGBuffer) {
  // Positions and normals are compared where the surface faces the camera at least this much.
  constexpr double kFacingNDotV = 0.2;
  struct Case {
    const char* scene;
    bool sphere;                // else the y = 0 plane
    double max_offset;          // largest distance between the two surfaces along the normal
    double max_normal_degrees;  // largest angle between their normals
  };
  // The plane's vertices lie exactly on y = 0, so its positions are exact. The sphere
  // mesh (64 x 32 quads of pi/32) lies up to 1 - cos^2(pi/64) = 2.4 mm inside the unit
  // sphere, and fp16 stores a position in [1, 2) to 2^-10 per component, so
  // sqrt(3) 2^-10 = 1.7 mm more. Where n.v >= kFacingNDotV that offset moves the hit
  // along the ray by at most offset / n.v, which on a unit sphere turns the normal by
  // as many radians.
  const double sagitta = 1.0 - std::pow(std::cos(ref::KIT_PI / 64.0), 2.0);
  const double sphere_offset = sagitta + std::sqrt(3.0) * std::ldexp(1.0, -10);
  const Case cases[] = {{"grazing", false, 1e-9, 1e-9},
                        {"sphere", true, sphere_offset, glm::degrees(sphere_offset / kFacingNDotV)}};
  for (const Case& c : cases) {
    const Scene& s = scene(c.scene);
    auto renderer = make_renderer("lighting", s, small_settings());
    const Frame frame = render_frame(*renderer, scene_frame_camera(s, small_settings()));
    size_t both = 0, gpu_only = 0, analytic_only = 0;
    double worst_offset = 0.0, worst_angle = 0.0, worst_albedo = 0.0, worst_roughness = 0.0;
    for (int y = 0; y < kSmallHeight; ++y) {
      for (int x = 0; x < kSmallWidth; ++x) {
        const ref::Ray ray = ref::camera_ray(frame.camera, kSmallWidth, kSmallHeight, x + 0.5, y + 0.5);
        const std::optional<ref::Hit> hit = c.sphere ? ref::intersect_sphere(ray, ref::dvec3(0.0), 1.0)
                                                     : ref::intersect_plane(ray, ref::dvec3(0.0), {0.0, 1.0, 0.0});
        const ref::SurfaceSample gpu = ref::gbuffer_sample(frame.gbuffer, x, y);
        if (!hit || !gpu.covered) {
          gpu_only += gpu.covered;
          analytic_only += hit.has_value();
          continue;
        }
        ++both;
        const ref::SurfaceSample exact = ref::surface_sample(*hit, s.materials[0]);
        worst_albedo = std::max(worst_albedo, glm::length(gpu.albedo - exact.albedo));
        worst_roughness = std::max(worst_roughness, std::fabs(gpu.roughness - exact.roughness));
        // Towards the outline a small depth difference moves the hit far along the ray.
        if (glm::dot(exact.normal, -ray.direction) < kFacingNDotV) continue;
        worst_offset = std::max(worst_offset, std::fabs(glm::dot(gpu.position - exact.position, exact.normal)));
        worst_angle = std::max(worst_angle, angle_degrees(gpu.normal, exact.normal));
      }
    }
    std::printf("[ reference ] analytic %s: %zu pixels on both, %zu rasterised only, %zu analytic only; offset %.3g, "
                "normal %.3g deg, albedo %.3g, roughness %.3g\n",
                c.scene, both, gpu_only, analytic_only, worst_offset, worst_angle, worst_albedo, worst_roughness);
    EXPECT_GT(both, kMinPixelsPerFrame) << c.scene;
    // Coverage differs only along the outline, where the mesh's polygon cuts inside the sphere.
    EXPECT_LE(gpu_only + analytic_only, c.sphere ? 150u : 0u) << c.scene;
    EXPECT_LE(worst_offset, c.max_offset) << c.scene;
    EXPECT_LE(worst_angle, c.max_normal_degrees) << c.scene;
    EXPECT_LE(worst_albedo, 0.5 / 255.0 * std::sqrt(3.0)) << c.scene << ": the RGBA8 albedo is rounded to 1/255";
    EXPECT_LE(worst_roughness, 1e-3) << c.scene << ": fp16 roughness";
  }
}

// A lab 2 whose BRDF uses alpha = roughness instead of roughness^2 must not pass
// the check the solution passes.
TEST(LabEquations, WrongBrdfFailsTheCheck) {
  const std::filesystem::path root = variant_root(
      "lab_equations_wrong_brdf",
      {{"02-lighting/brdf.glsl", "float alpha = roughness * roughness;", "float alpha = roughness;"}});
  size_t failures = 0, pixels = 0;
  for (const std::string scene_name : {"default", "sphere", "grazing"}) {
    const Scene& s = scene(scene_name);
    auto renderer = make_renderer("lighting", s, small_settings(), stage_library(find_stage("lighting"), root));
    const Frame frame = render_frame(*renderer, scene_frame_camera(s, small_settings()));
    const Agreement a = compare_with_reference(frame, ref::frame_lights(s, renderer->settings()),
                                               ref::shading_settings(renderer->settings(), 2), covered_pixels(frame));
    std::printf("[ reference ] wrong BRDF on %s: %s\n", scene_name.c_str(), describe(a).c_str());
    failures += a.failures;
    pixels += a.pixels;
  }
  EXPECT_GT(failures, 0u) << "a BRDF with alpha = roughness passed the reference check on " << pixels << " pixels";
}

}  // namespace
}  // namespace kit::test
