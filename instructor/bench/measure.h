#pragma once
// kit-bench's measurements: wall-clock frame times and error figures of one
// method on one scene configuration, and the CSV they are written to.
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "bench_metrics.h"
#include "bench_reference.h"
#include "bench_renderer.h"

namespace kit::bench {

// Frames rendered and discarded before timing (shader compilation, first-use
// allocation and llvmpipe's JIT happen there).
constexpr int kWarmupFrames = 2;
// Frames timed per configuration; the median is reported.
constexpr int kTimedFrames = 20;
// A configuration whose fastest warm-up frame takes longer than this is timed over
// kSlowTimedFrames frames: the full-screen loop and forward shading with 1024
// lights at 1280x720 take seconds per frame. The CSV's frames column says so.
constexpr double kSlowFrameSeconds = 2.0;
constexpr int kSlowTimedFrames = 3;

struct Timing {
  double median_ms = 0.0, min_ms = 0.0, max_ms = 0.0;
  int frames = 0;
};

// Wall-clock milliseconds of `frame` ended by glFinish.
double timed_ms(const std::function<void()>& frame);
// Median, fastest and slowest of some milliseconds (at least one).
Timing summarize(std::vector<double> ms);

// Times several methods on one scene configuration round-robin: after each
// method's `warmup` frames, round r renders one frame of every method in turn
// (every frame ended by glFinish, wall clock). Other processes on the machine
// then slow all methods alike, so the ratios between them hold even when the
// absolute times drift. Slow methods (see above) drop out after their frames.
std::vector<Timing> time_interleaved(BenchRenderer& renderer, const std::vector<const Method*>& methods,
                                     const FrameCamera& camera, int warmup, int frames);

// The IBL family's figures (measure_ibl.h): its rows compare with the reflectance
// integral at sampled pixels instead of with a reference image.
struct IblError {
  double max_relative = 0.0, mean_relative = 0.0;  // over the pixels (ibl_reference.h relative_error)
};
struct IblFigures {
  double precompute_ms = 0.0;  // the three maps (median of the runs)
  double irradiance_ms = 0.0;  // of which the irradiance map
  int pixels = 0;              // sampled covered pixels, per environment
  int integral_samples = 0;    // reflected_radiance_integral's samples a pixel
  std::vector<IblError> errors;  // one per kit_environment_names() (ibl.h), in its order
  size_t non_finite = 0;         // HDR pixels holding NaN or Inf, over the environments
};

// One measured configuration: a row of results.csv.
struct Row {
  std::string method, family, scene;
  int width = 0, height = 0;
  int small_lights = 0;     // the "lights" column: small lights added (bench_lights)
  int total_lights = 0;     // the scene's own lights + the small ones
  int bytes_per_pixel = 0;  // G-buffer bytes per pixel (0: forward has none)
  Timing timing;
  ErrorFigures hdr, ldr;    // linear HDR and display (after tone mapping) against the reference
  std::string reference;    // "cpu-double" or "gpu-fp32"
  double lights_per_pixel = 0.0;
  size_t triangles = 0;
  std::string small_light_range = "ranged";  // "ranged" or "unlimited" (bench_renderer.h SmallLightRange)
  std::optional<IblFigures> ibl;  // the IBL family only; hdr, ldr, lights_per_pixel and triangles then unused
};

// A row for `method` without its timing: one frame rendered and measured against
// `reference` (from reference_hdr with the same renderer and camera).
Row measure_accuracy(BenchRenderer& renderer, const Method& method, const FrameCamera& camera,
                     const Reference& reference, const std::string& scene_name, int small_lights);

// results.csv: the columns the issue names, then family, reference, frames,
// total_lights, lights_per_pixel, triangles, non_finite, small_light_range, and the
// IBL family's precompute_ms, irradiance_ms, ibl_pixels, integral_samples and, per
// environment E, max_rel_E and mean_rel_E (empty on the other rows, as are the IBL
// rows' image comparisons).
void write_csv(const std::string& path, const std::vector<Row>& rows);

}  // namespace kit::bench
