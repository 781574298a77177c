#pragma once
// kit-bench's IBL family (bench_ibl.h): each method's precompute time, stage 6's frame
// time, and its error against the reflectance integral at sampled pixels.
//
// The scene is rendered without its lights (and without the default rig), so the
// image is the environment's light alone plus emission, which is subtracted. One
// Renderer of the solutions' stage 6 per environment (kit_environment_names(): studio,
// sun); their G-buffers do not depend on the method, so the integral
// (ibl_reference.h reflected_radiance_integral) is estimated once per environment
// at the sampled pixels and every method is compared with the same estimates.
#include <functional>
#include <string>
#include <vector>

#include "bench_ibl.h"
#include "measure.h"

namespace kit::bench {

struct IblRun {
  int pixels;            // covered pixels sampled (evenly in row order), per environment
  int integral_samples;  // reflected_radiance_integral's samples a pixel
  int precompute_runs;   // the maps are precomputed this many times after a warm-up; the median is reported
  int warmup_frames, timed_frames;  // stage 6 frames, under the first environment
};
// The full run: 128 pixels of 65536 samples, about 12 s an environment on 2 cores (the
// integral's 5-standard-error bound stays within a few % at every pixel, and its mean
// under 1 %: well under the errors measured).
constexpr IblRun kIblFullRun{128, 65536, 5, 2, 10};
// --quick: a smoke test of the same code.
constexpr IblRun kIblQuickRun{8, 1024, 1, 1, 3};
// Relative errors are taken against max(|integral|, this): a tenth of the sky's
// radiance, so that dark pixels do not dominate (test_ibl uses the same).
constexpr double kIblErrorFloor = 0.02;

// Measures `methods` on `scene` (its lights are left out) from `camera` at settings' size; each
// row is passed to `on_row` as soon as it is complete. Frame times are taken under
// the first environment; the methods are timed one after the other (each needs its
// own maps), not round-robin.
std::vector<Row> measure_ibl(const std::vector<const IblMethod*>& methods, const Scene& scene,
                             const std::string& scene_name, const RenderSettings& settings, const FrameCamera& camera,
                             const IblRun& run, const std::function<void(const Row&)>& on_row);

}  // namespace kit::bench
