#pragma once
// How far an image is from its reference, as kit-bench reports it (through
// OpenImageIO's ImageBufAlgo::compare over the RGB channels).
#include "images/image_io.h"

namespace kit::bench {

// The "within one display step" threshold: a tone-mapped difference above it can
// change an 8-bit output value by more than one.
constexpr double kDisplayStep = 1.0 / 255.0;

struct ErrorFigures {
  double psnr = 0.0;             // dB, peak 1.0 (display white); +inf when identical
  double max_abs = 0.0;          // largest per-channel absolute difference
  double frac_over_step = 0.0;   // fraction of pixels with a channel differing by more than kDisplayStep
  size_t non_finite = 0;         // pixels of `image` holding NaN or Inf (compare skips nothing)
};

// Compares the RGB channels of two images of the same size; throws kit::Error otherwise.
ErrorFigures compare_images(const Image& image, const Image& reference);

}  // namespace kit::bench
