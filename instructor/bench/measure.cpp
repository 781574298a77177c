#include "measure.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>

#include "base/error.h"
#include "render/ibl.h"
#include "gl/pass_clock.h"

namespace kit::bench {

namespace {


std::string number(double v) {
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  if (std::isnan(v)) return "nan";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

}  // namespace

Timing summarize(std::vector<double> ms) {
  std::sort(ms.begin(), ms.end());
  Timing t;
  t.frames = static_cast<int>(ms.size());
  size_t n = ms.size();
  t.median_ms = n % 2 ? ms[n / 2] : 0.5 * (ms[n / 2 - 1] + ms[n / 2]);
  t.min_ms = ms.front();
  t.max_ms = ms.back();
  return t;
}

double timed_ms(const std::function<void()>& frame) {
  auto t0 = std::chrono::steady_clock::now();
  frame();
  glFinish();
  return 1000.0 * seconds_since(t0);
}

namespace {

double timed_frame(BenchRenderer& renderer, const Method& method, const FrameCamera& camera) {
  return timed_ms([&] { renderer.render(method, camera); });
}

}  // namespace

std::vector<Timing> time_interleaved(BenchRenderer& renderer, const std::vector<const Method*>& methods,
                                     const FrameCamera& camera, int warmup, int frames) {
  std::vector<int> wanted(methods.size(), frames);
  for (size_t m = 0; m < methods.size(); ++m) {
    double fastest = std::numeric_limits<double>::infinity();
    for (int i = 0; i < warmup; ++i) fastest = std::min(fastest, timed_frame(renderer, *methods[m], camera));
    if (fastest > 1000.0 * kSlowFrameSeconds) wanted[m] = std::min(frames, kSlowTimedFrames);
  }
  std::vector<std::vector<double>> ms(methods.size());
  for (int round = 0; round < frames; ++round)
    for (size_t m = 0; m < methods.size(); ++m)
      if (round < wanted[m]) ms[m].push_back(timed_frame(renderer, *methods[m], camera));
  std::vector<Timing> out;
  for (auto& samples : ms) out.push_back(summarize(samples));
  return out;
}

Row measure_accuracy(BenchRenderer& renderer, const Method& method, const FrameCamera& camera,
                     const Reference& reference, const std::string& scene_name, int small_lights) {
  Row row;
  row.method = method.name;
  row.family = method.family;
  row.scene = scene_name;
  row.width = renderer.settings().width;
  row.height = renderer.settings().height;
  row.small_lights = small_lights;
  row.total_lights = renderer.light_count();
  row.bytes_per_pixel = method.lighting == Lighting::Forward ? 0 : bytes_per_pixel(method.layout);
  renderer.render(method, camera);
  row.hdr = compare_images(renderer.read_hdr(), reference.hdr);
  row.ldr = compare_images(renderer.read_display(),
                           reference_display(reference.hdr, renderer.settings(), method.blur_passes));
  row.reference = reference.source;
  row.lights_per_pixel = renderer.lights_per_pixel();
  row.triangles = renderer.triangles(method, camera);
  return row;
}

void write_csv(const std::string& path, const std::vector<Row>& rows) {
  std::ofstream out(path);
  if (!out) throw Error(path + ": cannot write");
  out << "method,scene,size,lights,bytes_per_pixel,median_ms,min_ms,max_ms,psnr_hdr,max_abs_hdr,psnr_ldr,"
         "max_abs_ldr,frac_over_1_255,family,reference,frames,total_lights,lights_per_pixel,triangles,non_finite,"
         "small_light_range,precompute_ms,irradiance_ms,ibl_pixels,integral_samples";
  for (const std::string& environment : kit_environment_names()) out << ",max_rel_" << environment << ",mean_rel_" << environment;
  out << '\n';
  for (const Row& r : rows) {
    const IblFigures* ibl = r.ibl ? &*r.ibl : nullptr;
    // An IBL row has no image comparison, the others no IBL figures: their cells stay empty.
    auto image_figure = [&](double v) { return ibl ? std::string() : number(v); };
    out << r.method << ',' << r.scene << ',' << r.width << 'x' << r.height << ',' << r.small_lights << ','
        << r.bytes_per_pixel << ',' << number(r.timing.median_ms) << ',' << number(r.timing.min_ms) << ','
        << number(r.timing.max_ms) << ',' << image_figure(r.hdr.psnr) << ',' << image_figure(r.hdr.max_abs) << ','
        << image_figure(r.ldr.psnr) << ',' << image_figure(r.ldr.max_abs) << ',' << image_figure(r.ldr.frac_over_step)
        << ',' << r.family << ',' << r.reference << ',' << r.timing.frames << ',' << r.total_lights << ','
        << image_figure(r.lights_per_pixel) << ',' << (ibl ? std::string() : std::to_string(r.triangles)) << ','
        << (ibl ? ibl->non_finite : r.ldr.non_finite) << ',' << r.small_light_range;
    if (ibl) {
      out << ',' << number(ibl->precompute_ms) << ',' << number(ibl->irradiance_ms) << ',' << ibl->pixels << ','
          << ibl->integral_samples;
      for (const IblError& e : ibl->errors) out << ',' << number(e.max_relative) << ',' << number(e.mean_relative);
    } else {
      out << std::string(4 + 2 * kit_environment_names().size(), ',');
    }
    out << '\n';
  }
  if (!out) throw Error(path + ": write failed");
}

}  // namespace kit::bench
