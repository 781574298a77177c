// kit-bench: speed against accuracy of the deferred pipeline's methods.
//
//   kit-bench [--quick] [--out DIR]       the whole comparison: out/bench/results.csv and charts
//   kit-bench --ibl-only [--quick]        only the image-based lighting family (stage 6)
//   kit-bench --crowd-only [--quick]      only the lighting pass's benchmark scene (issue 13)
//   kit-bench --method NAME[,NAME...] [--scene FILE --size WxH --lights N]   one configuration
//                                         (several: timed round-robin under the same load)
//   kit-bench --list                      the method names
//
// Every method renders with the same framework (instructor/bench/bench_renderer.h), scene,
// lights and camera; frame times are wall clock over glFinish-ended frames, errors
// are measured against the CPU double-precision reference (instructor/bench/bench_reference.h).
// The IBL family (bench_ibl.h, measure_ibl.h) renders stage 6 itself and is measured
// against the reflectance integral at sampled pixels.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <iterator>

#include "cli.h"
#include "gl/context.h"
#include "cpu_reference.h"
#include "base/error.h"
#include "gl/pass_clock.h"
#include "measure.h"
#include "measure_ibl.h"
#include "bench_gbuffer.h"
#include "render/renderer.h"
#include "render/stages.h"

namespace fs = std::filesystem;

namespace {

// Debian's python3-matplotlib belongs to the system interpreter, which need not be
// the python3 first on PATH.
constexpr const char* kChartPython = "/usr/bin/python3";

// The full run's sizes and light counts (the configurations).
constexpr int kFullWidth = 1280, kFullHeight = 720;
const int kFullSmallLights[] = {32, 128, 256, 1024};
// --quick: a smoke test for CI, well under a minute on two cores.
constexpr int kQuickWidth = 320, kQuickHeight = 180;
const int kQuickSmallLights[] = {16, 64};
constexpr int kQuickWarmupFrames = 1;
constexpr int kQuickTimedFrames = 5;
const char* const kQuickIblMethods[] = {"ibl-default", "ibl-prefilter16", "ibl-sh2"};
// The lighting pass's benchmark (issue 13): kit-scenes' crowd scene, nine instances of a
// 19,200-triangle model and 32 point lights of its own, at 800 x 600 as the
// deferred-shading tutorial program it is compared with.
constexpr const char* kCrowdScene = "crowd";
constexpr int kCrowdWidth = 800, kCrowdHeight = 600;
constexpr int kQuickCrowdWidth = 200, kQuickCrowdHeight = 150;
const char* const kCrowdMethods[] = {"labs", "forward", "tiled-e256", "volumes-e256"};
// The labs' own stage whose frame is broken down: lighting, attenuation and tone mapping.
constexpr const char* kCrowdStage = "attenuation";
// The geometry pass against the least it could cost (issue 28): the labs' own (the
// solutions, with the framework's material variants) and a minimal one writing the same
// G-buffer from one UV set, no transform, vertex colour or MASK test, in alternating
// rounds so that their ratio holds under a changing machine load.
constexpr const char* kMinimalGeometryPass = "instructor/bench/minimal_gbuffer";
constexpr int kGeometryRounds = 5;
// Difference images are amplified so a one-step (1/255) error is visible.
constexpr int kDifferenceGain = 16;

struct Case {
  int small_lights;
  std::vector<std::string> methods;
};

std::vector<Case> plan(bool quick) {
  std::vector<Case> cases;
  std::vector<std::string> scene_methods, many_methods;
  if (quick) {
    scene_methods = {"reference", "labs", "gbuffer-lean16", "gbuffer-lean8", "volumes-e256", "tiled-e256",
                     "forward", "bloom6-full", "bloom6-half", "geometry-optimized"};
    many_methods = {"labs", "volumes-e256", "tiled-e256", "tiled-ref32-e1024", "forward"};
  } else {
    for (const kit::bench::Method& m : kit::bench::methods()) scene_methods.push_back(m.name);
    many_methods = {"labs", "volumes-e1024", "volumes-e256", "volumes-e64", "tiled-e1024",
                    "tiled-e256", "tiled-e64", "tiled-lean16-e1024", "tiled-ref32-e1024", "forward"};
  }
  cases.push_back({0, scene_methods});
  if (quick) {
    for (int n : kQuickSmallLights) cases.push_back({n, many_methods});
  } else {
    for (int n : kFullSmallLights) cases.push_back({n, many_methods});
  }
  return cases;
}

void usage() {
  std::printf(
      "usage: kit-bench [--quick] [--ibl-only] [--out DIR]\n"
      "       kit-bench --method NAME[,NAME...] [--scene FILE] [--size WxH] [--lights N] [--frames N]\n"
      "       kit-bench --list\n"
      "Times the deferred pipeline's methods (median of %d glFinish-ended frames after %d warm-up\n"
      "frames, wall clock) and measures each against the CPU double-precision reference.\n"
      "Without --method: the default scene at %dx%d with its own lights, then with 32, 256 and 1024\n"
      "small lights, then the crowd configuration (the crowd scene at 800x600 with its 32 lights, and\n"
      "the labs' own frame pass by pass with ns per covered pixel and light), then the IBL family (stage 6 without the scene's lights, measured against the\n"
      "reflectance integral at %d pixels under each kit environment); writes DIR/results.csv,\n"
      "speed_accuracy.png/.svg, lights_scaling.png/.svg and ibl_speed_accuracy.png/.svg\n"
      "(DIR defaults to out/bench under the kit root).\n"
      "  --quick               %dx%d, %d frames, fewer methods (CI smoke run)\n"
      "  --ibl-only            only the IBL family\n"
      "  --crowd-only          only the crowd configuration (prints it; writes DIR/results.csv)\n"
      "  --geometry-only       only the geometry pass of --scene against a minimal one (prints it)\n"
      "  --method NAME         one configuration: prints ms/frame and its error; several names\n"
      "                        separated by commas are timed round-robin on the same scene\n"
      "                        (IBL methods, ibl-*: one after the other, %d frames unless --frames;\n"
      "                        --passes and --images do not apply to them)\n"
      "  --frames N            timed frames (default %d)\n"
      "  --passes              with --method: median time of each pass (glFinish after each)\n"
      "  --images DIR          with --method: write the method's and the reference's display\n"
      "                        images and their difference (x%d) as PNG\n"
      "  --reference cpu|gpu   the reference: cpu (default) is the double-precision CPU evaluation\n"
      "                        where affordable (else gpu), gpu the RGBA32F full-screen loop\n"
      "  --list                the method names\n"
      "  --lights N            small lights added to the scene (bench_renderer.h small_lights)\n"
      "  --small-light-range on|off\n"
      "                        off: the small lights have no glTF range (inverse square to\n"
      "                        infinity), so culling them is never exact (default on)\n%s",
      kit::bench::kTimedFrames, kit::bench::kWarmupFrames, kFullWidth, kFullHeight, kit::bench::kIblFullRun.pixels,
      kQuickWidth, kQuickHeight,
      kQuickTimedFrames, kit::bench::kIblFullRun.timed_frames, kit::bench::kTimedFrames, kDifferenceGain, kit::common_options_help());
}

void list_methods() {
  for (const kit::bench::Method& m : kit::bench::methods()) {
    int bytes = m.lighting == kit::bench::Lighting::Forward ? 0 : kit::bench::bytes_per_pixel(m.layout);
    std::printf("%-20s %-9s %2d B/px  %s\n", m.name.c_str(), m.family.c_str(), bytes, m.summary.c_str());
  }
  const int ibl_bytes = kit::bench::bytes_per_pixel(kit::bench::labs_method().layout);
  for (const kit::bench::IblMethod& m : kit::bench::ibl_methods())
    std::printf("%-20s %-9s %2d B/px  %s\n", m.name.c_str(), kit::bench::kIblFamily, ibl_bytes, m.summary.c_str());
}

std::string over_255(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.2f/255", v * 255.0);
  return buf;
}

void print_ibl_row(const kit::bench::Row& r) {
  const kit::bench::IblFigures& f = *r.ibl;
  std::printf("%-20s %4dx%-4d precompute %8.1f ms (irradiance %6.1f ms)  frame %7.2f ms (min %.2f, max %.2f, %d frames)",
              r.method.c_str(), r.width, r.height, f.precompute_ms, f.irradiance_ms, r.timing.median_ms, r.timing.min_ms,
              r.timing.max_ms, r.timing.frames);
  for (size_t e = 0; e < f.errors.size(); ++e)
    std::printf("  %s max %.3f mean %.3f", kit::kit_environment_names()[e].c_str(), f.errors[e].max_relative,
                f.errors[e].mean_relative);
  std::printf("  [relative to the integral, %d px x %d samples]\n", f.pixels, f.integral_samples);
  std::fflush(stdout);
}

void print_row(const kit::bench::Row& r) {
  if (r.ibl) return print_ibl_row(r);
  std::printf("%-20s %4dx%-4d lights %4d (%.1f/px)  %9.2f ms (min %.2f, max %.2f, %d frames)  HDR %.1f dB max %.3g  "
              "display %.1f dB max %s, %.3f%% > 1/255  [%s]\n",
              r.method.c_str(), r.width, r.height, r.total_lights, r.lights_per_pixel, r.timing.median_ms, r.timing.min_ms,
              r.timing.max_ms, r.timing.frames, r.hdr.psnr, r.hdr.max_abs, r.ldr.psnr, over_255(r.ldr.max_abs).c_str(),
              100.0 * r.ldr.frac_over_step, r.reference.c_str());
  std::fflush(stdout);
}

// The last frame's display image, the reference's, and |difference| x kDifferenceGain.
void write_images(kit::bench::BenchRenderer& renderer, const kit::bench::Method& method,
                  const kit::bench::Reference& reference, const std::string& dir) {
  fs::create_directories(dir);
  kit::Image image = renderer.read_display();
  kit::Image ref = kit::bench::reference_display(reference.hdr, renderer.settings(), method.blur_passes);
  kit::Image diff = image;
  for (size_t i = 0; i < diff.pixels.size(); ++i)
    diff.pixels[i] = i % 4 == 3 ? 1.0f : kDifferenceGain * std::fabs(image.pixels[i] - ref.pixels[i]);
  kit::write_image(dir + "/" + method.name + ".png", image);
  kit::write_image(dir + "/reference-" + reference.source + ".png", ref);
  kit::write_image(dir + "/" + method.name + "-difference.png", diff);
}

// Median wall-clock time of each pass over `frames` frames, glFinish after every pass.
void print_passes(kit::bench::BenchRenderer& renderer, const kit::bench::Method& method,
                  const kit::FrameCamera& camera, int frames) {
  std::vector<kit::PassTimes> times(static_cast<size_t>(frames));
  for (kit::PassTimes& frame : times) renderer.render(method, camera, &frame);
  for (const auto& [pass, ms] : kit::median_pass_times(times))
    std::printf("  %-10s %9.2f ms (median of %d)\n", pass.c_str(), ms, frames);
}

const char* range_name(kit::bench::SmallLightRange range) {
  return range == kit::bench::SmallLightRange::Ranged ? "ranged" : "unlimited";
}

// One configuration's rows: `names` timed round-robin on `renderer` (so their ratios
// hold under a changing load), then each measured against `reference`, printed as it comes.
std::vector<kit::bench::Row> measure_methods(kit::bench::BenchRenderer& renderer, const std::vector<std::string>& names,
                                             const kit::FrameCamera& camera, const kit::bench::Reference& reference,
                                             const std::string& scene_name, int small_lights,
                                             kit::bench::SmallLightRange range, int warmup, int timed) {
  std::vector<const kit::bench::Method*> methods;
  for (const std::string& name : names) methods.push_back(&kit::bench::find_method(name));
  std::vector<kit::bench::Timing> timings = kit::bench::time_interleaved(renderer, methods, camera, warmup, timed);
  std::vector<kit::bench::Row> rows;
  for (size_t m = 0; m < methods.size(); ++m) {
    rows.push_back(kit::bench::measure_accuracy(renderer, *methods[m], camera, reference, scene_name, small_lights));
    rows.back().timing = timings[m];
    rows.back().small_light_range = range_name(range);
    print_row(rows.back());
  }
  return rows;
}

// Lab 7's light volumes as the labs run them (the kit's Renderer with the solutions at stage
// lightvolumes, not the bench's own volumes) on `lights`, against the same reference: where the
// lab's method stands beside the bench's tiles and volumes (lights_scaling.png). Bloom off,
// so the display is the loop's tone mapping, read as the 8-bit image; timed after the
// bench's methods, not round-robin with them. Lights per pixel: the fragments its volumes
// shaded (an occlusion query) over the pixels with a surface, plus the directional lights.
kit::bench::Row measure_lab_volumes(const kit::Scene& scene, const std::vector<kit::Light>& lights,
                                    const kit::RenderSettings& bench_settings, const kit::FrameCamera& camera,
                                    const kit::bench::Reference& reference, const std::string& scene_name,
                                    int small_lights, int warmup, int timed) {
  kit::Scene lit = scene;
  lit.lights = lights;
  kit::RenderSettings settings = bench_settings;
  settings.postprocess = false;
  settings.extra_lights = 0;
  settings.count_light_volume_work = true;
  const kit::Stage& stage = kit::find_stage("lightvolumes");
  kit::Renderer renderer(stage, kit::stage_library(stage, kit::kit_root() / "solutions"), lit, settings);
  for (int f = 0; f < warmup; ++f) renderer.render(camera);
  std::vector<double> ms;
  for (int f = 0; f < timed; ++f) ms.push_back(kit::bench::timed_ms([&] { renderer.render(camera); }));
  kit::bench::Row row;
  row.method = "lab7-volumes";
  row.family = "lighting";
  row.scene = scene_name;
  row.width = settings.width;
  row.height = settings.height;
  row.small_lights = small_lights;
  row.total_lights = static_cast<int>(lights.size());
  row.bytes_per_pixel = kit::bench::bytes_per_pixel(kit::bench::Layout::Seed002);
  row.timing = kit::bench::summarize(ms);
  row.hdr = kit::bench::compare_images(renderer.read_view(kit::View::Hdr, true), reference.hdr);
  row.ldr = kit::bench::compare_images(renderer.read_view(kit::View::Final, true),
                                       kit::bench::reference_display(reference.hdr, settings, 0));
  row.reference = reference.source;
  const kit::LightVolumeWork& work = renderer.light_volume_work();
  if (work.surface_pixels > 0)
    row.lights_per_pixel = static_cast<double>(work.shaded_fragments) / static_cast<double>(work.surface_pixels) +
                           static_cast<double>(lights.size()) - static_cast<double>(work.volume_lights);
  print_row(row);
  return row;
}

// The labs' own Renderer (the solutions) on `scene`: each pass's median time, and the
// lighting pass per covered pixel and light, the figure issue 13 sets at <= 5 ns.
void print_labs_breakdown(const kit::Scene& scene, const kit::RenderSettings& settings,
                          const kit::FrameCamera& camera, int warmup, int frames) {
  const kit::Stage& stage = kit::find_stage(kCrowdStage);
  kit::Renderer renderer(stage, kit::stage_library(stage, kit::kit_root() / "solutions"), scene, settings);
  for (int f = 0; f < warmup; ++f) renderer.render(camera);
  std::vector<kit::PassTimes> times(static_cast<size_t>(frames));
  for (kit::PassTimes& frame : times) renderer.render(camera, &frame);
  const size_t covered = kit::reference::covered_pixels(kit::reference::read_gbuffer(renderer)).size();
  const int lights = static_cast<int>(kit::frame_lights(scene, stage, settings).size());
  std::printf("  the labs' own stage %s (solutions), median of %d frames, glFinish after each pass:\n",
              stage.name.c_str(), frames);
  double total = 0.0;
  for (const auto& [pass, ms] : kit::median_pass_times(times)) {
    total += ms;
    std::printf("    %-10s %8.2f ms", pass.c_str(), ms);
    if (pass == "lighting" && covered > 0 && lights > 0)
      std::printf("   %.2f ns per covered pixel and light (%zu covered pixels, %d lights)",
                  1e6 * ms / (static_cast<double>(covered) * lights), covered, lights);
    std::printf("\n");
  }
  std::printf("    %-10s %8.2f ms\n", "sum", total);
}

// One round of `frames` frames: the median time of `renderer`'s geometry pass.
double median_geometry_ms(kit::Renderer& renderer, const kit::FrameCamera& camera, int frames) {
  std::vector<kit::PassTimes> times(static_cast<size_t>(frames));
  for (kit::PassTimes& frame : times) renderer.render(camera, &frame);
  for (const auto& [pass, ms] : kit::median_pass_times(times))
    if (pass == "geometry") return ms;
  throw kit::Error("kit-bench: the gbuffer stage timed no geometry pass");
}

// The labs' geometry pass and the minimal one on `scene`, kGeometryRounds alternating
// rounds: the median of each and of the per-round ratios (docs/performance.md has the
// figures on LearnOpenGL 8.1's scene: kit-bench --geometry-only --scene FILE).
void print_geometry_against_minimal(const kit::Scene& scene, const std::string& scene_name,
                                    const kit::RenderSettings& settings, const kit::FrameCamera& camera, int warmup,
                                    int frames) {
  const kit::Stage& stage = kit::find_stage("gbuffer");
  kit::Renderer labs(stage, kit::stage_library(stage, kit::kit_root() / "solutions"), scene, settings);
  kit::Renderer minimal(stage, kit::stage_library(stage, kit::kit_root() / kMinimalGeometryPass), scene, settings);
  for (int f = 0; f < warmup; ++f) {
    labs.render(camera);
    minimal.render(camera);
  }
  std::vector<double> labs_ms, minimal_ms, ratios;
  for (int round = 0; round < kGeometryRounds; ++round) {
    labs_ms.push_back(median_geometry_ms(labs, camera, frames));
    minimal_ms.push_back(median_geometry_ms(minimal, camera, frames));
    ratios.push_back(labs_ms.back() / minimal_ms.back());
  }
  const auto [lo, hi] = std::minmax_element(ratios.begin(), ratios.end());
  std::printf("-- geometry pass on '%s' at %dx%d, %d rounds of %d frames (%s):\n", scene_name.c_str(),
              settings.width, settings.height, kGeometryRounds, frames, labs.texture_compression().reason.c_str());
  std::printf("  the labs' (material variants) %8.2f ms\n  minimal                       %8.2f ms\n"
              "  ratio                         %8.2f (per round %.2f to %.2f)\n",
              kit::median(labs_ms), kit::median(minimal_ms), kit::median(ratios), *lo, *hi);
}

kit::FrameCamera camera_for(const kit::Scene& scene, const kit::RenderSettings& s) {
  kit::Camera camera = scene.camera ? *scene.camera : kit::framing_camera(scene);
  return kit::frame_camera(camera, static_cast<float>(s.width) / static_cast<float>(s.height));
}

}  // namespace

int main(int argc, char** argv) {
  auto t0 = std::chrono::steady_clock::now();
  kit::CommonOptions options;
  bool quick = false, list = false, size_given = false, passes = false, ibl_only = false, crowd_only = false,
       geometry_only = false;
  std::string method_name, out_dir, images_dir;
  int frames = -1;
  kit::bench::SmallLightRange small_range = kit::bench::SmallLightRange::Ranged;
  double cpu_budget = kit::bench::kCpuReferenceBudget;
  return kit::run_tool("kit-bench", 1, [&]() -> int {
    for (int i = 1; i < argc; ++i) {
      if (!std::strcmp(argv[i], "--help") || !std::strcmp(argv[i], "-h")) {
        usage();
        return 0;
      }
      if (!std::strcmp(argv[i], "--size") || !std::strcmp(argv[i], "-s")) size_given = true;
    }
    kit::parse_options(argc, argv, options, [&](const std::string& flag, const kit::OptionValue& value) -> int {
      if (flag == "--quick") return quick = true, 1;
      if (flag == "--ibl-only") return ibl_only = true, 1;
      if (flag == "--crowd-only") return crowd_only = true, 1;
      if (flag == "--geometry-only") return geometry_only = true, 1;
      if (flag == "--list") return list = true, 1;
      if (flag == "--passes") return passes = true, 1;
      if (flag == "--out") return out_dir = value(), 2;
      if (flag == "--method") return method_name = value(), 2;
      if (flag == "--frames") return frames = std::atoi(value().c_str()), 2;
      if (flag == "--images") return images_dir = value(), 2;
      if (flag == "--small-light-range") {
        small_range = kit::parse_on_off(value(), flag) ? kit::bench::SmallLightRange::Ranged
                                                       : kit::bench::SmallLightRange::Unlimited;
        return 2;
      }
      if (flag == "--reference") {
        std::string which = value();
        if (which != "cpu" && which != "gpu") throw kit::Error("--reference expects cpu or gpu (got '" + which + "')");
        cpu_budget = which == "gpu" ? 0.0 : kit::bench::kCpuReferenceBudget;
        return 2;
      }
      return 0;
    });
    if (list) {
      list_methods();
      return 0;
    }
    auto context = kit::create_headless_context(kit::parse_backend(options.backend));
    const kit::Scene scene = kit::load_scene(kit::resolve_scene(options.scene));
    kit::RenderSettings settings = options.settings;
    if (geometry_only) {
      print_geometry_against_minimal(scene, options.scene, settings, camera_for(scene, settings),
                                     quick ? kQuickWarmupFrames : kit::bench::kWarmupFrames,
                                     frames > 0 ? frames : quick ? kQuickTimedFrames : kit::bench::kTimedFrames);
      return 0;
    }

    if (!method_name.empty()) {
      // One method, or several separated by commas: those are timed round-robin
      // (time_interleaved), so their ratios hold under a changing machine load.
      std::vector<const kit::bench::Method*> methods;
      std::vector<const kit::bench::IblMethod*> ibl_methods;
      for (size_t begin = 0; begin <= method_name.size();) {
        size_t end = std::min(method_name.find(',', begin), method_name.size());
        const std::string name = method_name.substr(begin, end - begin);
        if (const kit::bench::IblMethod* ibl = kit::bench::find_ibl_method(name))
          ibl_methods.push_back(ibl);
        else
          methods.push_back(&kit::bench::find_method(name));
        begin = end + 1;
      }
      if (!ibl_methods.empty()) {
        kit::bench::IblRun run = kit::bench::kIblFullRun;
        if (frames > 0) run.timed_frames = frames;
        std::printf("%s\n", context->describe().c_str());
        kit::bench::measure_ibl(ibl_methods, scene, options.scene, settings, camera_for(scene, settings), run, print_row);
        if (methods.empty()) return 0;
      }
      kit::bench::BenchRenderer renderer(scene, kit::bench::bench_lights(scene, settings.extra_lights, small_range), settings);
      kit::FrameCamera camera = camera_for(scene, settings);
      kit::bench::Reference reference = kit::bench::reference_hdr(renderer, camera, cpu_budget);
      const int timed = frames > 0 ? frames : kit::bench::kTimedFrames;
      std::vector<kit::bench::Timing> timings =
          kit::bench::time_interleaved(renderer, methods, camera, kit::bench::kWarmupFrames, timed);
      std::printf("%s\n", context->describe().c_str());
      for (size_t m = 0; m < methods.size(); ++m) {
        kit::bench::Row row = kit::bench::measure_accuracy(renderer, *methods[m], camera, reference, options.scene,
                                                           settings.extra_lights);
        row.timing = timings[m];
        row.small_light_range = range_name(small_range);
        print_row(row);
        if (passes) print_passes(renderer, *methods[m], camera, timed);
        if (!images_dir.empty()) write_images(renderer, *methods[m], reference, images_dir);
      }
      return 0;
    }

    if (!size_given) {
      settings.width = quick ? kQuickWidth : kFullWidth;
      settings.height = quick ? kQuickHeight : kFullHeight;
    }
    const int warmup = quick ? kQuickWarmupFrames : kit::bench::kWarmupFrames;
    const int timed = frames > 0 ? frames : quick ? kQuickTimedFrames : kit::bench::kTimedFrames;
    fs::path out = out_dir.empty() ? kit::kit_root() / "out" / "bench" : fs::path(out_dir);
    fs::create_directories(out);
    std::printf("kit-bench%s on %s, scene '%s' at %dx%d\n", quick ? " --quick" : "", context->describe().c_str(),
                options.scene.c_str(), settings.width, settings.height);

    std::vector<kit::bench::Row> rows;
    for (const Case& c : ibl_only || crowd_only ? std::vector<Case>{} : plan(quick)) {
      kit::bench::BenchRenderer renderer(scene, kit::bench::bench_lights(scene, c.small_lights, small_range), settings);
      kit::FrameCamera camera = camera_for(scene, settings);
      auto t_ref = std::chrono::steady_clock::now();
      kit::bench::Reference reference = kit::bench::reference_hdr(renderer, camera, cpu_budget);
      std::printf("-- %d lights (%d small): reference %s in %.1f s\n", renderer.light_count(), c.small_lights,
                  reference.source.c_str(), kit::seconds_since(t_ref));
      for (kit::bench::Row& row : measure_methods(renderer, c.methods, camera, reference, options.scene,
                                                  c.small_lights, small_range, warmup, timed))
        rows.push_back(std::move(row));
      if (c.small_lights > 0)
        rows.push_back(measure_lab_volumes(scene, kit::bench::bench_lights(scene, c.small_lights, small_range), settings,
                                           camera, reference, options.scene, c.small_lights, warmup, timed));
      kit::bench::write_csv((out / "results.csv").string(), rows);  // partial results survive an interruption
    }
    if (!ibl_only) {
      // The crowd configuration: its own scene, size and lights; the labs' own frame pass
      // by pass, then the labs' loop against the other lighting methods.
      const kit::Scene crowd = kit::load_scene(kit::resolve_scene(kCrowdScene));
      kit::RenderSettings crowd_settings = settings;
      crowd_settings.width = quick ? kQuickCrowdWidth : kCrowdWidth;
      crowd_settings.height = quick ? kQuickCrowdHeight : kCrowdHeight;
      kit::FrameCamera camera = camera_for(crowd, crowd_settings);
      print_labs_breakdown(crowd, crowd_settings, camera, warmup, timed);
      print_geometry_against_minimal(crowd, kCrowdScene, crowd_settings, camera, warmup, timed);
      kit::bench::BenchRenderer renderer(crowd, kit::bench::bench_lights(crowd, 0, small_range), crowd_settings);
      kit::bench::Reference reference = kit::bench::reference_hdr(renderer, camera, cpu_budget);
      std::printf("-- %s scene at %dx%d, %d lights: reference %s\n", kCrowdScene, crowd_settings.width,
                  crowd_settings.height, renderer.light_count(), reference.source.c_str());
      const std::vector<std::string> crowd_methods(std::begin(kCrowdMethods), std::end(kCrowdMethods));
      for (kit::bench::Row& row : measure_methods(renderer, crowd_methods, camera, reference, kCrowdScene, 0,
                                                  small_range, warmup, timed))
        rows.push_back(std::move(row));
      kit::bench::write_csv((out / "results.csv").string(), rows);
      if (crowd_only) return 0;
    }
    std::vector<const kit::bench::IblMethod*> ibl_methods;
    if (quick) {
      for (const char* name : kQuickIblMethods) ibl_methods.push_back(kit::bench::find_ibl_method(name));
    } else {
      for (const kit::bench::IblMethod& m : kit::bench::ibl_methods()) ibl_methods.push_back(&m);
    }
    auto t_ibl = std::chrono::steady_clock::now();
    kit::bench::IblRun run = quick ? kit::bench::kIblQuickRun : kit::bench::kIblFullRun;
    if (frames > 0) run.timed_frames = frames;
    for (kit::bench::Row& row : kit::bench::measure_ibl(ibl_methods, scene, options.scene, settings,
                                                        camera_for(scene, settings), run, print_row))
      rows.push_back(std::move(row));
    kit::bench::write_csv((out / "results.csv").string(), rows);
    std::printf("-- IBL family: %zu methods in %.0f s\n", ibl_methods.size(), kit::seconds_since(t_ibl));
    std::string charts = std::string(kChartPython) + " \"" + (kit::kit_root() / "instructor" / "bench" / "charts.py").string() +
                         "\" \"" + (out / "results.csv").string() + "\" \"" + out.string() + "\"";
    if (std::system(charts.c_str()) != 0) throw kit::Error("the chart script failed: " + charts);
    std::printf("wrote %s/results.csv and its charts (.png/.svg) in %.0f s\n",
                out.string().c_str(), kit::seconds_since(t0));
    return 0;
  });
}
