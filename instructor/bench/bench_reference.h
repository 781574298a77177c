#pragma once
// The image every bench method is measured against: the CPU double-precision
// evaluation of the labs' equations (cpu_reference.h) on the reference layout's
// RGBA32F G-buffer where that is affordable, else the GPU reference method (the
// same G-buffer, the full-screen loop in fp32 into an RGBA32F target).
#include <string>

#include "bench_renderer.h"

namespace kit::bench {

// Pixel-light evaluations the CPU reference may take before the GPU reference is
// used instead: about 1280 x 720 x 256 (tens of seconds on two cores).
constexpr double kCpuReferenceBudget = 2.5e8;

struct Reference {
  Image hdr;           // linear HDR (RGBA)
  std::string source;  // "cpu-double" or "gpu-fp32"
};

// Renders reference_method() with `renderer` and evaluates the reference HDR image.
// `cpu_budget` below width * height * lights forces the GPU reference.
Reference reference_hdr(BenchRenderer& renderer, const FrameCamera& camera, double cpu_budget = kCpuReferenceBudget);

// The reference display image (double precision, cpu_reference.h final_image): tone
// mapping, or with blur_passes > 0 the labs' full-resolution bloom with that many passes.
Image reference_display(const Image& hdr, const RenderSettings& settings, int blur_passes);

}  // namespace kit::bench
