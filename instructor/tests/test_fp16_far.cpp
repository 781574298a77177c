// Stability case 5: a scene far from the origin. Moving the whole scene (geometry,
// lights and camera) changes nothing physically, so a stable pipeline renders the
// same image. Seed 002's G-buffer stores world positions in RGBA16F, whose step is
// 0.5 m at x = 1000 and 8 m at x = 10000: the lighting bands (the witness). The lean
// layout reconstructs positions from depth relative to the camera, in double on the
// CPU and then in float around the camera, so it stays within its usual error.
#include <glm/gtc/matrix_transform.hpp>

#include <cstdio>

#include "bench_metrics.h"
#include "bench_reference.h"
#include "bench_renderer.h"
#include "kit_test.h"

namespace kit::bench {
namespace {

constexpr int kWidth = 160, kHeight = 90;
const float kTranslations[] = {1000.0f, 10000.0f};

// The witness: RGBA16F world positions at these distances put this many pixels
// more than one display step off (at x = 1000 a position step is 0.5 m, the size of
// a checker square).
constexpr double kBandedFraction = 0.10;
// The stable layout may lose no more than this, relative to its own error at the
// origin: float camera-relative reconstruction and the float geometry pass (vertex
// positions rounded to 1 mm at x = 10000) move a few silhouette pixels.
constexpr double kStableExtraFraction = 0.01;

// The scene moved by `offset`: every draw, light and the camera.
Scene translated(const Scene& scene, glm::vec3 offset) {
  Scene out = scene;
  const glm::mat4 move = glm::translate(glm::mat4(1.0f), offset);
  for (DrawItem& d : out.draws) d.world = move * d.world;
  for (Light& l : out.lights) l.position += offset;
  Camera camera = scene.camera ? *scene.camera : framing_camera(scene);
  camera.view = camera.view * glm::translate(glm::mat4(1.0f), -offset);
  camera.position += offset;
  out.camera = camera;
  out.bounds_min += offset;
  out.bounds_max += offset;
  return out;
}

FrameCamera camera_of(const Scene& scene) {
  return frame_camera(*scene.camera, static_cast<float>(kWidth) / static_cast<float>(kHeight));
}

TEST(Fp16Far, HalfFloatPositionsBandWhileDepthReconstructionStays) {
  test::context();
  RenderSettings settings;
  settings.width = kWidth;
  settings.height = kHeight;
  const Scene origin = translated(test::scene("default"), glm::vec3(0.0f));
  // The truth: the CPU reference at the origin.
  BenchRenderer at_origin(origin, origin.lights, settings);
  Reference reference = reference_hdr(at_origin, camera_of(origin));
  const Image truth = reference_display(reference.hdr, settings, 0);

  auto error_of = [&](const Scene& scene, const char* method) {
    BenchRenderer renderer(scene, scene.lights, settings);
    renderer.render(find_method(method), camera_of(scene));
    return compare_images(renderer.read_display(), truth);
  };
  const ErrorFigures labs0 = error_of(origin, "labs");
  const ErrorFigures lean0 = error_of(origin, "gbuffer-lean16");
  std::printf("x = %6.0f: seed 002 (RGBA16F positions) max %6.2f/255, %6.2f%% over 1/255; "
              "lean (depth, camera-relative) max %6.2f/255, %6.2f%%\n",
              0.0, 255.0 * labs0.max_abs, 100.0 * labs0.frac_over_step, 255.0 * lean0.max_abs,
              100.0 * lean0.frac_over_step);
  for (float x : kTranslations) {
    const Scene far = translated(origin, glm::vec3(x, 0.0f, 0.0f));
    const ErrorFigures labs = error_of(far, "labs");
    const ErrorFigures lean = error_of(far, "gbuffer-lean16");
    std::printf("x = %6.0f: seed 002 (RGBA16F positions) max %6.2f/255, %6.2f%% over 1/255; "
                "lean (depth, camera-relative) max %6.2f/255, %6.2f%%\n",
                x, 255.0 * labs.max_abs, 100.0 * labs.frac_over_step, 255.0 * lean.max_abs,
                100.0 * lean.frac_over_step);
    // Witness: the labs' layout really breaks here.
    EXPECT_GT(labs.frac_over_step, kBandedFraction) << "x = " << x;
    // The kit's method does not.
    EXPECT_LE(lean.frac_over_step, lean0.frac_over_step + kStableExtraFraction) << "x = " << x;
    EXPECT_EQ(lean.non_finite, 0u);
  }
}

}  // namespace
}  // namespace kit::bench
