// kit-bench's methods (instructor/bench/bench_renderer.h) render what they claim: each agrees
// with the CPU double-precision reference within the bound its error source allows,
// the culling methods equal the full-screen loop when nothing is culled, and the
// bench's "labs" configuration is the labs' own Renderer. Accuracy only: speed is
// measured by kit-bench, never asserted here.
#include <cmath>
#include <cstdio>
#include <string>

#include "bench_metrics.h"
#include "bench_reference.h"
#include "bench_renderer.h"
#include "base/error.h"
#include "gbuffer_layout.h"
#include "kit_test.h"

namespace kit::bench {
namespace {

// Small enough that every method and the CPU reference take well under a second.
constexpr int kWidth = 160, kHeight = 90;

// An epsilon so small that every light's cut-off radius exceeds the scene: light
// volumes and tiles then cull nothing and must equal the full-screen loop.
constexpr float kNoCullingEpsilon = 1e-5f;

// What the culling methods may differ from the loop by when nothing is culled, in
// linear HDR relative to the value: light volumes add each light into the RGBA16F
// target, so every addition rounds to half precision (2^-11 relative) once more
// than the loop's single write; a pixel lit by n lights may drift by about n
// roundings. Tiled shading writes once, like the loop.
constexpr double kHalfUlp = 1.0 / 2048.0;

struct Bound {
  const char* method;
  double max_display;   // largest display (tone-mapped) difference, in 1/255 steps
  double max_fraction;  // fraction of pixels allowed more than one step off
  const char* why;      // the error source the bound allows for
};

// Measured on this scene at this size (kit-bench --method NAME --size 160x90: the
// fraction is 0 or at most 0.007 % there) and rounded up to leave room for compiler
// and driver differences.
const Bound kBounds[] = {
    {"reference", 0.25, 0.0, "fp32 against double on the same G-buffer"},
    {"labs", 3.0, 0.001, "RGBA16F position and normal: millimetre positions move sharp highlights"},
    {"gbuffer-ref32", 0.5, 0.0, "the RGBA16F HDR target's rounding only"},
    {"gbuffer-lean16", 1.0, 0.0, "24-bit depth, 16-bit octahedral normal, 8-bit roughness and emission (the 1/255 target)"},
    {"gbuffer-lean8", 40.0, 0.02, "8-bit octahedral normal: about half a degree, visible in sharp highlights"},
    {"volumes-e1024", 3.0, 0.001, "as labs: the scene's own lights reach everything"},
    {"volumes-e64", 3.0, 0.001, "as labs: the scene's own lights reach everything"},
    {"tiled-e1024", 3.0, 0.001, "as labs"},
    {"tiled-e64", 3.0, 0.001, "as labs"},
    {"tiled-lean16-e1024", 1.0, 0.0, "as gbuffer-lean16"},
    {"tiled-ref32-e1024", 0.5, 0.0, "as gbuffer-ref32"},
    {"forward", 1.5, 0.001, "no G-buffer, so none of the reference's 8-bit albedo rounding"},
    {"bloom6-full", 4.0, 0.01, "bright-pass threshold flips from the RGBA16F G-buffer"},
    {"bloom6-half", 90.0, 0.6, "half-resolution bright pass and blur: edges of bright areas soften"},
    {"geometry-optimized", 3.0, 0.001, "as labs: reordering only changes depth-tie winners"},
};

// Largest |image - loop| / max(|loop|, 1e-3) over all channels, in linear HDR.
double largest_relative_difference(const Image& image, const Image& loop) {
  double worst = 0.0;
  for (size_t i = 0; i < image.pixels.size(); ++i) {
    const double scale = std::max(std::fabs(static_cast<double>(loop.pixels[i])), 1e-3);
    worst = std::max(worst, std::fabs(image.pixels[i] - loop.pixels[i]) / scale);
  }
  return worst;
}

class BenchMethods : public ::testing::Test {
 protected:
  void SetUp() override {
    test::context();
    settings_.width = kWidth;
    settings_.height = kHeight;
  }
  FrameCamera camera(const Scene& scene) const {
    Camera c = scene.camera ? *scene.camera : framing_camera(scene);
    return frame_camera(c, static_cast<float>(kWidth) / static_cast<float>(kHeight));
  }
  RenderSettings settings_;
};

TEST_F(BenchMethods, EachMethodAgreesWithTheCpuReferenceWithinItsBound) {
  const Scene& scene = test::scene("default");
  BenchRenderer renderer(scene, bench_lights(scene, 0), settings_);
  const FrameCamera cam = camera(scene);
  Reference reference = reference_hdr(renderer, cam);
  ASSERT_EQ(reference.source, "cpu-double");
  for (const Bound& b : kBounds) {
    SCOPED_TRACE(b.method);
    const Method& m = find_method(b.method);
    renderer.render(m, cam);
    ErrorFigures e = compare_images(renderer.read_display(), reference_display(reference.hdr, settings_, m.blur_passes));
    std::printf("%-20s display max %6.2f/255, %.4f%% over 1/255 (bound %.0f/255, %.2f%%: %s)\n", b.method,
                e.max_abs * 255.0, 100.0 * e.frac_over_step, b.max_display, 100.0 * b.max_fraction, b.why);
    EXPECT_EQ(e.non_finite, 0u);
    EXPECT_LE(e.max_abs * 255.0, b.max_display);
    EXPECT_LE(e.frac_over_step, b.max_fraction);
  }
}

TEST_F(BenchMethods, EveryListedMethodHasABound) {
  for (const Method& m : methods()) {
    if (m.family == "bloom" && m.name != "bloom6-full" && m.name != "bloom6-half") continue;  // one per resolution
    if (m.name == "volumes-e256" || m.name == "tiled-e256") continue;  // between the two checked epsilons
    bool found = false;
    for (const Bound& b : kBounds) found = found || m.name == b.method;
    EXPECT_TRUE(found) << m.name << " has no accuracy bound in this test";
  }
}

TEST_F(BenchMethods, CullingMethodsEqualTheLoopWhenNothingIsCulled) {
  const Scene& scene = test::scene("default");
  // The scene's lights and small ones without a range, so several lights overlap
  // at every pixel and only epsilon bounds the radii.
  constexpr int kSmallLights = 16;
  BenchRenderer renderer(scene, bench_lights(scene, kSmallLights, SmallLightRange::Unlimited), settings_);
  const FrameCamera cam = camera(scene);
  renderer.render(labs_method(), cam);
  const Image loop = renderer.read_hdr();
  const double lights = renderer.light_count();
  for (const char* name : {"volumes-e1024", "tiled-e1024"}) {
    SCOPED_TRACE(name);
    Method m = find_method(name);
    m.epsilon = kNoCullingEpsilon;
    renderer.render(m, cam);
    EXPECT_DOUBLE_EQ(renderer.lights_per_pixel(), lights);
    const double worst = largest_relative_difference(renderer.read_hdr(), loop);
    const double allowed = (m.lighting == Lighting::Volumes ? lights + 1.0 : 1.0) * kHalfUlp;
    std::printf("%s against the loop: largest relative HDR difference %.2e (allowed %.2e)\n", name, worst, allowed);
    EXPECT_LE(worst, allowed);
  }
}

// Small lights with a glTF range add exactly nothing past it (lab 3's window), so
// a radius capped at the range culls without error: at epsilon 1/1024 (whose bound
// lies beyond every small light's range) volumes and tiles drop most lights yet
// equal the loop to the HDR target's rounding. Witness: the same lights without a
// range, culled at the same epsilon, lose their inverse-square tails and differ
// from their loop by several display steps.
TEST_F(BenchMethods, CullingAtTheRangeIsExact) {
  const Scene& scene = test::scene("default");
  constexpr int kSmallLights = 256;
  const FrameCamera cam = camera(scene);
  for (const Light& light : small_lights(scene, kSmallLights)) {
    Light unlimited = light;
    unlimited.range = 0.0f;
    ASSERT_LT(light.range, light_cutoff_radius(unlimited, 1.0f / 1024.0f, 0)) << "the range must be the smaller radius";
  }
  for (SmallLightRange range : {SmallLightRange::Ranged, SmallLightRange::Unlimited}) {
    const bool ranged = range == SmallLightRange::Ranged;
    BenchRenderer renderer(scene, bench_lights(scene, kSmallLights, range), settings_);
    renderer.render(labs_method(), cam);
    const Image loop_hdr = renderer.read_hdr();
    const Image loop_display = renderer.read_display();
    for (const char* name : {"volumes-e1024", "tiled-e1024"}) {
      SCOPED_TRACE(std::string(name) + (ranged ? ", ranged lights" : ", unlimited lights"));
      const Method& m = find_method(name);
      renderer.render(m, cam);
      const double lights = renderer.lights_per_pixel();
      const double worst = largest_relative_difference(renderer.read_hdr(), loop_hdr);
      const double display = compare_images(renderer.read_display(), loop_display).max_abs * 255.0;
      std::printf("%s, %s lights: %.1f of %d lights per pixel, largest relative HDR difference %.2e, display %.2f/255\n",
                  name, ranged ? "ranged" : "unlimited", lights, renderer.light_count(), worst, display);
      EXPECT_LT(lights, 0.25 * renderer.light_count()) << "most lights should be culled";
      if (ranged) {
        // Tiles write once, as the loop does; volumes round once per blended light
        // (bounded in CullingMethodsEqualTheLoopWhenNothingIsCulled), so for them
        // the display bound is the claim.
        if (m.lighting == Lighting::Tiled) {
          EXPECT_LE(worst, kHalfUlp);
        }
        EXPECT_LE(display, 1.0);
      } else {
        EXPECT_GT(display, 3.0) << "witness: culling lights without a range should lose visible light";
      }
    }
  }
}

TEST_F(BenchMethods, CulledLightsAreTheOnlyDifferenceFromTheLoop) {
  // With a real epsilon, volumes and tiles drop the same terms (the same radius
  // test per pixel), so they agree with each other far better than with the loop.
  const Scene& scene = test::scene("default");
  BenchRenderer renderer(scene, bench_lights(scene, 64), settings_);
  const FrameCamera cam = camera(scene);
  renderer.render(find_method("volumes-e256"), cam);
  const Image volumes = renderer.read_display();
  const double volume_lights = renderer.lights_per_pixel();
  renderer.render(find_method("tiled-e256"), cam);
  const Image tiled = renderer.read_display();
  EXPECT_DOUBLE_EQ(renderer.lights_per_pixel(), volume_lights);
  EXPECT_LT(volume_lights, renderer.light_count()) << "epsilon 1/256 should cull some of 68 lights";
  ErrorFigures between = compare_images(volumes, tiled);
  std::printf("volumes-e256 against tiled-e256: display max %.2f/255\n", between.max_abs * 255.0);
  EXPECT_LE(between.max_abs * 255.0, 1.0);
}

TEST_F(BenchMethods, LabsConfigurationIsTheLabsRenderer) {
  settings_.postprocess = false;
  auto labs = test::render_stage("normalmap", "default", settings_);
  const Image expected = labs->read_view(View::Hdr, true);
  const Scene& scene = test::scene("default");
  BenchRenderer renderer(scene, bench_lights(scene, 0), settings_);
  renderer.render(labs_method(), camera(scene));
  const Image image = renderer.read_hdr();
  // Same shaders, same order of operations; at most one half-precision rounding apart.
  double worst = 0.0;
  for (size_t i = 0; i < image.pixels.size(); ++i) {
    double scale = std::max(std::fabs(static_cast<double>(expected.pixels[i])), 1e-3);
    worst = std::max(worst, std::fabs(image.pixels[i] - expected.pixels[i]) / scale);
  }
  EXPECT_LE(worst, kHalfUlp);
}

TEST_F(BenchMethods, Bloom6FullIsTheLabsPostprocessStage) {
  // Stage 5 with the free-choice effect off: bright pass, 6 blur passes, composite.
  auto labs = test::render_stage("postprocess", "default", settings_);
  const Image expected = labs->read_view(View::Final, false);  // 8-bit
  const Scene& scene = test::scene("default");
  BenchRenderer renderer(scene, bench_lights(scene, 0), settings_);
  renderer.render(find_method("bloom6-full"), camera(scene));
  const Image image = renderer.read_display();  // before 8-bit rounding
  // The Renderer's image is rounded to 8 bits: half a step, plus float noise.
  constexpr double kRounding = 0.5 / 255.0 + 1e-4;
  EXPECT_LE(test::max_abs_difference(image, expected), kRounding);
}

// A directional light (the sun scene's) reaches everywhere: the loop and forward
// methods shade it as the labs do (l = -direction, no falloff) and agree with the CPU
// reference, while light volumes and tiles, which bound each light by a sphere
// around its position, refuse it by name instead of culling it at a radius.
// Witness: a sphere of light_cutoff_radius would be infinite for it.
TEST_F(BenchMethods, DirectionalLightIsShadedByTheLoopAndRefusedByCulling) {
  const Scene& scene = test::scene("sun");
  int directional = -1;
  for (size_t i = 0; i < scene.lights.size(); ++i)
    if (scene.lights[i].type == KIT_LIGHT_DIRECTIONAL) directional = static_cast<int>(i);
  ASSERT_GE(directional, 0) << "the sun scene has a directional light";
  EXPECT_TRUE(std::isinf(light_cutoff_radius(scene.lights[static_cast<size_t>(directional)], 1.0f / 1024.0f, 0)));
  BenchRenderer renderer(scene, bench_lights(scene, 0), settings_);
  const FrameCamera cam = camera(scene);
  const Reference reference = reference_hdr(renderer, cam);
  ASSERT_EQ(reference.source, "cpu-double");
  for (const char* name : {"reference", "forward"}) {
    SCOPED_TRACE(name);
    const Method& m = find_method(name);
    renderer.render(m, cam);
    const ErrorFigures e = compare_images(renderer.read_display(), reference_display(reference.hdr, settings_, m.blur_passes));
    std::printf("sun scene, %s: display max %.2f/255\n", name, e.max_abs * 255.0);
    EXPECT_EQ(e.non_finite, 0u);
    EXPECT_LE(e.max_abs * 255.0, 1.5);
  }
  for (const char* name : {"volumes-e64", "tiled-e64"}) {
    SCOPED_TRACE(name);
    try {
      renderer.render(find_method(name), cam);
      ADD_FAILURE() << name << " rendered a directional light";
    } catch (const Error& e) {
      const std::string message = e.what();
      EXPECT_NE(message.find(std::string("method '") + name + "'"), std::string::npos) << message;
      EXPECT_NE(message.find("light " + std::to_string(directional) + " is directional"), std::string::npos) << message;
    }
  }
}

TEST(BenchLayouts, BytesPerPixel) {
  EXPECT_EQ(bytes_per_pixel(Layout::Seed002), GBuffer::bytes_per_pixel());
  EXPECT_EQ(bytes_per_pixel(Layout::Reference), 56);
  // The lean layout's target: at least 35 % fewer bytes than seed 002's.
  EXPECT_LE(bytes_per_pixel(Layout::Lean16), 0.65 * bytes_per_pixel(Layout::Seed002));
  EXPECT_LT(bytes_per_pixel(Layout::Lean8), bytes_per_pixel(Layout::Lean16));
}

}  // namespace
}  // namespace kit::bench
