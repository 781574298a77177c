#include "measure_ibl.h"

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <thread>

#include "base/error.h"
#include "ibl_reference.h"
#include "gl/pass_clock.h"
#include "render/stages.h"

namespace kit::bench {

namespace reference = kit::reference;
using glm::dvec3;

namespace {

// The integral's estimates are seeded per pixel, so every run compares with the same values.
constexpr std::uint64_t kIntegralSeed = 1234u;
// reflected_radiance_integral's bound: |value - integral| < 5 standard errors (ibl_reference.h).
constexpr double kStandardErrors = 5.0;

// One environment: stage 6 rendering it, and the integral at the sampled pixels.
struct Environment {
  std::string name;
  Image image;
  std::unique_ptr<Renderer> renderer;
  std::vector<std::pair<int, int>> pixels;
  std::vector<reference::SurfaceSample> samples;
  std::vector<dvec3> integral;
  dvec3 eye{0.0};  // the camera's position
};


Environment prepare(const std::string& name, const Scene& scene, RenderSettings settings, const FrameCamera& camera,
                    const IblRun& run) {
  const auto t0 = std::chrono::steady_clock::now();
  Environment e;
  e.name = name;
  e.eye = dvec3(camera.position);
  e.image = load_environment(resolve_environment(name));
  settings.environment = name;
  settings.extra_lights = 0;
  settings.default_light_rig = false;
  settings.ibl = IblSettings{};
  const Stage& stage = find_stage("ibl");
  e.renderer = std::make_unique<Renderer>(stage, stage_library(stage, kit_root() / "solutions"), scene, settings);
  e.renderer->render(camera);
  const reference::GBufferImages gbuffer = reference::read_gbuffer(*e.renderer);
  const std::vector<std::pair<int, int>> covered = reference::covered_pixels(gbuffer);
  if (covered.empty()) throw Error("the IBL bench's scene covers no pixel");
  const size_t stride = std::max<size_t>(covered.size() / static_cast<size_t>(run.pixels), 1);
  for (size_t i = stride / 2; i < covered.size() && e.pixels.size() < static_cast<size_t>(run.pixels); i += stride) {
    e.pixels.push_back(covered[i]);
    e.samples.push_back(reference::gbuffer_sample(gbuffer, covered[i].first, covered[i].second));
  }

  // The estimates are independent: pixels are shared out over every core.
  std::vector<reference::IntegralEstimate> estimates(e.pixels.size());
  const size_t threads = std::max(1u, std::thread::hardware_concurrency());
  std::vector<std::thread> workers;
  for (size_t t = 0; t < threads; ++t)
    workers.emplace_back([&, t] {
      for (size_t i = t; i < e.pixels.size(); i += threads)
        estimates[i] = reference::reflected_radiance_integral(e.image, e.samples[i], e.eye,
                                                              run.integral_samples, kIntegralSeed + i);
    });
  for (std::thread& w : workers) w.join();
  double largest_bound = 0.0, mean_bound = 0.0;
  for (const reference::IntegralEstimate& estimate : estimates) {
    e.integral.push_back(estimate.value);
    const double bound = reference::relative_error(estimate.value + kStandardErrors * estimate.standard_error,
                                                   estimate.value, kIblErrorFloor);
    largest_bound = std::max(largest_bound, bound);
    mean_bound += bound / static_cast<double>(estimates.size());
  }
  std::printf("-- IBL under '%s': the integral at %zu pixels, %d samples each, in %.1f s (5 standard errors, relative: "
              "up to %.3f, mean %.3f)\n",
              name.c_str(), e.pixels.size(), run.integral_samples, seconds_since(t0), largest_bound, mean_bound);
  std::fflush(stdout);
  return e;
}

// The irradiance map made from order-2 spherical harmonics instead of irradiance.frag;
// its milliseconds (projection, evaluation and upload).
double set_sh2_irradiance(const IblMethod& method, Environment& e) {
  return timed_ms([&] {
    e.renderer->image_based_lighting()->set_irradiance(
        sh2_irradiance_map(project_sh2(e.image), method.settings.irradiance_size));
  });
}

IblError errors_against_integral(const Environment& e) {
  const Image hdr = e.renderer->read_view(View::Hdr, true);
  IblError error;
  for (size_t i = 0; i < e.pixels.size(); ++i) {
    const auto [x, y] = e.pixels[i];
    const double relative = reference::relative_error(reference::pixel_rgb(hdr, x, y) - e.samples[i].emission,
                                                      e.integral[i], kIblErrorFloor);
    // KIT_IBL_DEBUG: the pixels far off, with the split sum in double to tell its error from the GPU's.
    if (std::getenv("KIT_IBL_DEBUG") && relative > 0.3)
      std::printf("  %s pixel %d,%d roughness %.2f metallic %.2f: GPU %.4f, split sum %.4f, integral %.4f (green)\n",
                  e.name.c_str(), x, y, e.samples[i].roughness, e.samples[i].metallic,
                  reference::pixel_rgb(hdr, x, y).y - e.samples[i].emission.y,
                  reference::split_sum_radiance(e.image, e.samples[i], e.eye).y, e.integral[i].y);
    error.max_relative = std::max(error.max_relative, relative);
    error.mean_relative += relative / static_cast<double>(e.pixels.size());
  }
  return error;
}

}  // namespace

std::vector<Row> measure_ibl(const std::vector<const IblMethod*>& methods, const Scene& scene,
                             const std::string& scene_name, const RenderSettings& settings, const FrameCamera& camera,
                             const IblRun& run, const std::function<void(const Row&)>& on_row) {
  Scene unlit = scene;
  unlit.lights.clear();
  std::vector<Environment> environments;
  for (const std::string& name : kit_environment_names())
    environments.push_back(prepare(name, unlit, settings, camera, run));

  std::vector<Row> rows;
  for (const IblMethod* method : methods) {
    Row row;
    row.method = method->name;
    row.family = kIblFamily;
    row.scene = scene_name;
    row.width = settings.width;
    row.height = settings.height;
    row.bytes_per_pixel = bytes_per_pixel(labs_method().layout);
    row.reference = "cpu-integral";
    row.small_light_range.clear();
    IblFigures figures;
    figures.pixels = static_cast<int>(environments.front().pixels.size());
    figures.integral_samples = run.integral_samples;
    for (Environment& e : environments) {
      Renderer& renderer = *e.renderer;
      renderer.settings().ibl = method->settings;
      renderer.render(camera);  // precomputes the maps for the new settings
      if (&e != &environments.front()) {
        if (method->irradiance == IrradianceSource::Sh2) {
          set_sh2_irradiance(*method, e);
          renderer.render(camera);
        }
      } else {
        // Precompute and frame times under the first environment. Reloading the shaders
        // precomputes the maps again (the programs' compilation is not counted); the
        // precompute of render() above, the first with these settings, is the warm-up.
        std::vector<double> precompute_ms, irradiance_ms;
        for (int k = 0; k < run.precompute_runs; ++k) {
          renderer.reload_shaders();
          const ImageBasedLighting& ibl = *renderer.image_based_lighting();
          precompute_ms.push_back(1000.0 * ibl.precompute_seconds());
          irradiance_ms.push_back(1000.0 * ibl.irradiance_seconds());
        }
        if (method->irradiance == IrradianceSource::Sh2) {
          // The lab's irradiance pass replaced by the method's.
          for (int k = 0; k < run.precompute_runs; ++k) {
            const double ms = set_sh2_irradiance(*method, e);
            precompute_ms[k] += ms - irradiance_ms[k];
            irradiance_ms[k] = ms;
          }
        }
        figures.precompute_ms = summarize(precompute_ms).median_ms;
        figures.irradiance_ms = summarize(irradiance_ms).median_ms;
        for (int k = 0; k < run.warmup_frames; ++k) renderer.render(camera);
        std::vector<double> frame_ms;
        for (int k = 0; k < run.timed_frames; ++k) frame_ms.push_back(timed_ms([&] { renderer.render(camera); }));
        row.timing = summarize(frame_ms);
      }
      figures.errors.push_back(errors_against_integral(e));
      figures.non_finite += renderer.count_non_finite(View::Hdr);
    }
    row.ibl = figures;
    rows.push_back(row);
    on_row(row);
  }
  return rows;
}

}  // namespace kit::bench
