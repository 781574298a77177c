// Stability case 7: the camera inside a light volume. Seen from inside a sphere
// every face points away from the camera, so the usual back-face culling drops the
// whole volume and the light vanishes (the witness). The kit draws back faces only
// (front faces culled) with depth clamping, so every covered pixel is shaded once
// and the result is the full-screen loop's.
#include <cstdio>

#include "bench_renderer.h"
#include "gbuffer_layout.h"
#include "kit_test.h"

namespace kit::bench {
namespace {

constexpr int kWidth = 160, kHeight = 90;
// One light half a metre in front of the camera, bright enough to light the scene.
constexpr float kLightDistance = 0.5f;  // metres along the view direction
constexpr float kLightIntensity = 2.0f; // candela
// Radius sqrt(I / (pi epsilon)) = 80 m: the volume holds the camera and the whole
// scene, so nothing is culled and only the volume's rasterisation is under test.
constexpr float kEpsilon = 1e-4f;
// Additive blending rounds to half precision once more than the loop writes:
// 2^-11 relative, doubled for the single light plus the base pass.
constexpr double kAllowedRelative = 2.0 / 2048.0;
// A pixel counts as lit when the light adds more than this to it (linear HDR).
constexpr double kLitThreshold = 1e-3;

TEST(LightVolumeInside, BackFacesKeepTheLightFrontFacesLoseIt) {
  test::context();
  RenderSettings settings;
  settings.width = kWidth;
  settings.height = kHeight;
  const Scene& scene = test::scene("default");
  const FrameCamera camera =
      frame_camera(*scene.camera, static_cast<float>(kWidth) / static_cast<float>(kHeight));
  Light light;
  light.type = KIT_LIGHT_POINT;
  const glm::vec3 forward = -glm::vec3(glm::inverse(camera.view)[2]);
  light.position = camera.position + kLightDistance * forward;
  light.intensity = kLightIntensity;
  BenchRenderer renderer(scene, {light}, settings);

  Method loop = labs_method();
  renderer.render(loop, camera);
  const Image expected = renderer.read_hdr();
  BenchRenderer unlit(scene, {}, settings);
  unlit.render(loop, camera);
  const Image dark = unlit.read_hdr();

  Method volumes = find_method("volumes-e1024");
  volumes.epsilon = kEpsilon;
  renderer.render(volumes, camera);
  const Image kept = renderer.read_hdr();
  Method naive = volumes;
  naive.cull_front_faces = false;
  renderer.render(naive, camera);
  const Image lost = renderer.read_hdr();

  size_t lit = 0, lit_in_naive = 0;
  double worst = 0.0;
  for (size_t i = 0; i < expected.pixels.size(); i += 4) {
    for (size_t c = i; c < i + 3; ++c) {
      double scale = std::max(std::fabs(static_cast<double>(expected.pixels[c])), 1e-3);
      worst = std::max(worst, std::fabs(kept.pixels[c] - expected.pixels[c]) / scale);
    }
    if (expected.pixels[i + 1] - dark.pixels[i + 1] > kLitThreshold) {
      ++lit;
      if (lost.pixels[i + 1] - dark.pixels[i + 1] > kLitThreshold) ++lit_in_naive;
    }
  }
  std::printf("camera inside the volume: %zu pixels lit by the light; front faces drawn: %zu of them lit; "
              "back faces drawn: largest relative difference from the loop %.2e\n",
              lit, lit_in_naive, worst);
  ASSERT_GT(lit, static_cast<size_t>(kWidth * kHeight / 2)) << "the light should light most of the view";
  // Witness: the naive volume loses the light everywhere.
  EXPECT_EQ(lit_in_naive, 0u);
  // The kit's volume is the loop.
  EXPECT_LE(worst, kAllowedRelative);
}

}  // namespace
}  // namespace kit::bench
