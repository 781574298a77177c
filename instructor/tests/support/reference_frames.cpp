#include "reference_frames.h"

#include <glm/gtc/matrix_transform.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "kit_test.h"

namespace kit::test {

using reference::dvec3;

std::unique_ptr<Renderer> make_renderer(const std::string& stage, const Scene& scene, const RenderSettings& settings) {
  return make_renderer(stage, scene, settings, stage_library(find_stage(stage), kit_root() / "solutions"));
}

std::unique_ptr<Renderer> make_renderer(const std::string& stage, const Scene& scene, const RenderSettings& settings,
                                        ShaderLibrary library) {
  context();
  return std::make_unique<Renderer>(find_stage(stage), std::move(library), scene, settings);
}

FrameCamera scene_frame_camera(const Scene& scene, const RenderSettings& settings) {
  const Camera camera = scene.camera ? *scene.camera : framing_camera(scene);
  return frame_camera(camera, static_cast<float>(settings.width) / static_cast<float>(settings.height));
}

FrameCamera look_at_camera(glm::vec3 eye, glm::vec3 target, float yfov, const RenderSettings& settings, float znear,
                           float zfar) {
  const glm::vec3 forward = glm::normalize(target - eye);
  // lookAt degenerates when the view runs along its up vector.
  const glm::vec3 up = std::fabs(forward.y) > 0.99f ? glm::vec3(0, 0, -1) : glm::vec3(0, 1, 0);
  Camera camera;
  camera.view = glm::lookAt(eye, target, up);
  camera.position = eye;
  camera.yfov = yfov;
  camera.znear = znear;
  camera.zfar = zfar;
  return frame_camera(camera, static_cast<float>(settings.width) / static_cast<float>(settings.height));
}

FrameCamera sphere_silhouette_camera(const Scene& sphere, const RenderSettings& settings) {
  const glm::vec3 silhouette(std::sqrt(15.0f) / 4.0f, 0.0f, 0.25f);
  return look_at_camera(scene_frame_camera(sphere, settings).position, silhouette, 0.01f, settings);
}

Frame render_frame(Renderer& renderer, const FrameCamera& camera) {
  renderer.render(camera);
  glFinish();
  Frame frame;
  frame.gbuffer = reference::read_gbuffer(renderer);
  frame.hdr = renderer.read_view(View::Hdr, true);
  frame.final = renderer.read_view(View::Final, false);
  frame.camera = camera;
  frame.stage = renderer.stage().number;
  return frame;
}

dvec3 stored_ldr(const Image& image, int x, int y) { return glm::round(pixel_rgb(image, x, y) * 255.0) / 255.0; }

bool finite(dvec3 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

double angle_degrees(dvec3 a, dvec3 b) {
  const double c = glm::dot(glm::normalize(a), glm::normalize(b));
  return glm::degrees(std::acos(std::min(1.0, std::max(-1.0, c))));
}

double n_dot_v(const Frame& frame, int x, int y) {
  const reference::SurfaceSample s = reference::gbuffer_sample(frame.gbuffer, x, y);
  if (!s.covered) return NAN;
  return glm::dot(glm::normalize(s.normal), glm::normalize(dvec3(frame.camera.position) - s.position));
}

PixelList covered_pixels(const Frame& frame) { return reference::covered_pixels(frame.gbuffer); }

PixelList grazing_pixels(const Frame& frame, double max_n_dot_v) {
  PixelList out;
  for (const auto& [x, y] : covered_pixels(frame))
    if (n_dot_v(frame, x, y) < max_n_dot_v) out.emplace_back(x, y);
  return out;
}

Agreement compare_with_reference(const Frame& frame, const std::vector<Light>& lights,
                                 const reference::ShadingSettings& settings, const PixelList& pixels) {
  const std::vector<reference::ShadingLight> uploaded = reference::uploaded_lights(lights);
  const dvec3 eye(frame.camera.position);
  Agreement a;
  for (const auto& [x, y] : pixels) {
    const reference::SurfaceSample sample = reference::gbuffer_sample(frame.gbuffer, x, y);
    const dvec3 ref = reference::shade(sample, eye, uploaded, settings);
    const dvec3 ref_display = reference::display(ref, settings);
    const dvec3 ldr = stored_ldr(frame.final, x, y);
    double hdr_error = 0.0, raw_error = 0.0, ldr_error = 0.0;
    for (int c = 0; c < 3; ++c) {
      const double gpu = frame.hdr.at(x, y, c);
      const double scale = std::max(std::fabs(ref[c]), reference::kHalfMinNormal);
      // Distance from the GPU value to the fp16 values either side of the reference:
      // zero when the GPU stored the reference, rounded either way.
      const reference::HalfNeighbours stored = reference::half_neighbours(ref[c]);
      const double outside = gpu < stored.below ? stored.below - gpu : gpu > stored.above ? gpu - stored.above : 0.0;
      double e = outside / scale, raw = std::fabs(gpu - ref[c]) / scale;
      if (!std::isfinite(gpu) || !std::isfinite(ref[c]) || std::isnan(e)) e = raw = INFINITY;
      hdr_error = std::max(hdr_error, e);
      raw_error = std::max(raw_error, raw);
      double d = std::fabs(ldr[c] - ref_display[c]);
      ldr_error = std::max(ldr_error, std::isnan(d) ? INFINITY : d);
    }
    ++a.pixels;
    if (hdr_error > a.max_hdr_relative || a.worst.empty()) {
      char text[256];
      std::snprintf(text, sizeof text, "pixel (%d, %d): GPU (%.7g, %.7g, %.7g), reference (%.7g, %.7g, %.7g), n.v %.3g",
                    x, y, frame.hdr.at(x, y, 0), frame.hdr.at(x, y, 1), frame.hdr.at(x, y, 2), ref.x, ref.y, ref.z,
                    n_dot_v(frame, x, y));
      a.worst = text;
    }
    a.max_hdr_relative = std::max(a.max_hdr_relative, hdr_error);
    a.max_hdr_raw_relative = std::max(a.max_hdr_raw_relative, raw_error);
    a.max_ldr_abs = std::max(a.max_ldr_abs, ldr_error);
    if (hdr_error <= kHdrRelativeTolerance)
      ++a.hdr_within;
    else if (ldr_error <= kLdrTolerance)
      ++a.ldr_within_only;
    else
      ++a.failures;
  }
  return a;
}

std::string describe(const Agreement& a) {
  char text[320];
  std::snprintf(text, sizeof text,
                "%zu pixels: %zu within HDR bound, %zu within 1/255 displayed only, %zu failing; "
                "max HDR rel. error %.3g beyond fp16 storage (%.3g including it), max displayed abs. error %.3g (%.2f/255)",
                a.pixels, a.hdr_within, a.ldr_within_only, a.failures, a.max_hdr_relative, a.max_hdr_raw_relative, a.max_ldr_abs,
                a.max_ldr_abs * 255.0);
  return text + std::string("; worst ") + a.worst;
}

}  // namespace kit::test
