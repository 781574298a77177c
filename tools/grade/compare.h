#pragma once
// Comparing a submission's render with its reference, idiff-style
// (OpenImageIO's ImageBufAlgo::compare for the per-channel metrics; the angle
// between normals for Metric::Normal), and the images the report shows.
#include <string>

#include "checks.h"
#include "config.h"
#include "image_io.h"

namespace kit::grade {

struct Comparison {
  bool passed = false;
  double max_error = 0.0;        // largest per-channel difference (Normal: degrees)
  int max_x = 0, max_y = 0;      // where it is
  double mean_error = 0.0;
  double failing_percent = 0.0;  // pixels over the per-pixel threshold (Changes: pixels changed)
  double psnr = 0.0;             // dB, of the compared values (inf when identical)
  size_t non_finite = 0;         // pixels of the submission holding NaN or Inf
  std::string summary;           // the numbers in one line of words
  std::string note;              // why it failed when that needs saying (NaN, empty image, size)
  Image diff;                    // |submission - reference| x 16 through a colour map (RGB)
};

// Compares `image` (the submission's) with `reference` under `metric`.
Comparison compare_images(Metric metric, const Tolerance& tolerance, const Image& image, const Image& reference);

// The image as the report shows it (RGB, [0,1]): G-buffer vectors as (v+1)/2,
// positions over the reference's bounds, HDR through Reinhard and gamma 2.2,
// NaN/Inf pixels magenta. `reference` supplies the bounds for positions.
Image display_image(Metric metric, const Image& image, const Image& reference);

// Factor the report's diff images scale |a - b| by before the colour map.
constexpr float kDiffScale = 16.0f;

}  // namespace kit::grade
