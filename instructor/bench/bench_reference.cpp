#include "bench_reference.h"

#include <algorithm>
#include <thread>

#include "cpu_reference.h"
#include "gbuffer_layout.h"

namespace kit::bench {

namespace {

// The stage whose equations the bench's methods evaluate: falloff, Reinhard and
// gamma, normal mapping, no bloom (stage 4); bloom rows use stage 5.
constexpr int kShadingStage = 4;
constexpr int kBloomStage = 5;

// Rows [begin, end) of `image` as an image of their own.
Image rows(const Image& image, int begin, int end) {
  Image out(image.width, end - begin, image.channels);
  const size_t row = static_cast<size_t>(image.width) * image.channels;
  std::copy_n(image.pixels.begin() + static_cast<std::ptrdiff_t>(row * begin), row * (end - begin), out.pixels.begin());
  return out;
}

}  // namespace

Reference reference_hdr(BenchRenderer& renderer, const FrameCamera& camera, double cpu_budget) {
  renderer.render(reference_method(), camera);
  const RenderSettings& s = renderer.settings();
  const double work = static_cast<double>(s.width) * s.height * std::max(renderer.light_count(), 1);
  if (work > cpu_budget) return {renderer.read_hdr(), "gpu-fp32"};

  std::vector<Image> g = renderer.read_gbuffer();
  const auto lights = reference::uploaded_lights(renderer.lights());
  const auto settings = reference::shading_settings(s, kShadingStage);
  const glm::dvec3 eye(camera.position);
  // shade_gbuffer is single-threaded: bands of rows run on every core.
  const int bands = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  std::vector<Image> results(static_cast<size_t>(bands));
  std::vector<std::thread> workers;
  for (int b = 0; b < bands; ++b) {
    workers.emplace_back([&, b] {
      const int begin = s.height * b / bands, end = s.height * (b + 1) / bands;
      reference::GBufferImages band{rows(g[KIT_GBUF_POSITION], begin, end), rows(g[KIT_GBUF_NORMAL], begin, end),
                                    rows(g[KIT_GBUF_ALBEDO], begin, end), rows(g[KIT_GBUF_MATERIAL], begin, end),
                                    rows(g[KIT_GBUF_EMISSION], begin, end)};
      results[static_cast<size_t>(b)] = reference::shade_gbuffer(band, eye, lights, settings);
    });
  }
  for (std::thread& t : workers) t.join();
  Image hdr(s.width, s.height, 4);
  auto out = hdr.pixels.begin();
  for (const Image& band : results) out = std::copy(band.pixels.begin(), band.pixels.end(), out);
  return {hdr, "cpu-double"};
}

Image reference_display(const Image& hdr, const RenderSettings& s, int blur_passes) {
  auto settings = reference::shading_settings(s, blur_passes > 0 ? kBloomStage : kShadingStage);
  settings.postprocess = true;
  settings.blur_passes = blur_passes;
  return reference::final_image(hdr, settings);
}

}  // namespace kit::bench
