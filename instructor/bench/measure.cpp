#include "measure.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>

#include "error.h"

namespace kit::bench {

namespace {

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

std::string number(double v) {
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  if (std::isnan(v)) return "nan";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

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

double timed_frame(BenchRenderer& renderer, const Method& method, const FrameCamera& camera) {
  auto t0 = std::chrono::steady_clock::now();
  renderer.render(method, camera);
  glFinish();
  return 1000.0 * seconds_since(t0);
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
         "max_abs_ldr,frac_over_1_255,family,reference,frames,total_lights,lights_per_pixel,triangles,non_finite,small_light_range\n";
  for (const Row& r : rows) {
    out << r.method << ',' << r.scene << ',' << r.width << 'x' << r.height << ',' << r.small_lights << ','
        << r.bytes_per_pixel << ',' << number(r.timing.median_ms) << ',' << number(r.timing.min_ms) << ','
        << number(r.timing.max_ms) << ',' << number(r.hdr.psnr) << ',' << number(r.hdr.max_abs) << ','
        << number(r.ldr.psnr) << ',' << number(r.ldr.max_abs) << ',' << number(r.ldr.frac_over_step) << ','
        << r.family << ',' << r.reference << ',' << r.timing.frames << ',' << r.total_lights << ','
        << number(r.lights_per_pixel) << ',' << r.triangles << ',' << r.ldr.non_finite << ','
        << r.small_light_range << '\n';
  }
  if (!out) throw Error(path + ": write failed");
}

}  // namespace kit::bench
