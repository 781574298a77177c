#pragma once
// Comparing a submission's render with its reference, idiff-style (the statistics
// of OpenImageIO's ImageBufAlgo::compare for the per-channel metrics, computed here in
// one pass; the angle between normals for Metric::Normal), and the images the report shows.
#include <array>
#include <set>
#include <string>
#include <vector>

#include "frames/checks.h"
#include "images/image_io.h"
#include "render/light_volumes.h"
#include "verdict/config.h"

namespace kit::grade {

struct Comparison {
  bool passed = false;
  double max_error = 0.0;        // largest per-channel difference (Normal: degrees)
  int max_x = 0, max_y = 0;      // where it is
  int width = 0, height = 0;     // the compared images' size (the report marks max_x, max_y on them)
  double mean_error = 0.0;
  double failing_percent = 0.0;  // pixels over the per-pixel threshold (Changes: pixels changed)
  size_t failing_pixels = 0;     // the same as a count
  size_t allowed_failing_pixels = 0;  // the most that may fail (fail_percent of the image, rounded down)
  size_t edge_pixels = 0;        // pixels at the reference's edges over the threshold that its neighbourhood
                                 // explains (a renderer may draw an edge one pixel over: compare.cpp, is_edge)
  size_t filter_pixels = 0;      // pixels over the threshold that the reference's filter allowance explains
  size_t covered_pixels = 0;     // pixels where the reference or the submission shows more than the background
  double covered_mean_error = 0.0;  // mean per-pixel error over them (largest channel difference; Normal: degrees),
                                    // each pixel's capped at fail_threshold
  double psnr = 0.0;             // dB, of the compared values (inf when identical)
  size_t non_finite = 0;         // pixels of the submission holding NaN or Inf
  // Where the error lies, coarsely (diagnosis.h): the image cut into kSignatureColumns x
  // kSignatureRows tiles, row by row, each the mean of its pixels' errors (those the mean error
  // criterion averages) over fail_threshold, each capped at kSignatureCap. (Each tile's signed
  // mean difference beside it named a relative of a left-out mistake first for at most 74 of
  // 125 against 73, and fewer at larger weights: not kept.) Empty for metrics that compare no
  // pixels with a reference (changes, same, work).
  std::vector<float> signature;
  std::string summary;           // the numbers in one line of words
  std::string note;              // why it failed when that needs saying (NaN, empty image, size)
  // A failed comparison's worst pixel (max_x, max_y): your value and the reference's there (for
  // a G-buffer attachment, the channel that differs most), then, where the grader knows them
  // (lab_verdict.h, describe_pixel_inputs), the inputs the lab's shaders had there.
  std::string worst_pixel;
  Image diff;                    // |submission - reference| x 16 through a colour map (RGB)
};

// The largest difference a metric can measure between two pixels (a hard_fail at
// or above it never fires): 1 for RGBA8 images, 2 for compressed HDR (c / (1 + |c|)
// lies in (-1, 1), so only a sign flip differs by more than 1), 180 degrees for
// normals, twice RGBA16F's largest value for positions and materials.
double largest_possible_difference(Metric metric);
// The most pixels of `pixels` that may fail the per-pixel threshold: fail_percent of them, rounded down.
size_t allowed_failing_pixels(const Tolerance& tolerance, size_t pixels);

// Whether every pixel of `image` has the first pixel's values (a NaN never matches).
bool is_uniform(const Image& image);

// A reference's background: the value of the pixels where nothing is drawn, as
// compare_images finds it (the reference's most common pixel as compared under the
// metric: NaN zeroed, HDR compressed; the smallest such value on a tie).
using Background = std::array<float, 4>;
// Every pixel of `reference` counted: a run finds each reference's once and passes it to
// compare_images, rather than counting the same reference again for every submission.
Background reference_background(Metric metric, const Image& reference);

// Each pixel's difference between `image` and `reference` under `metric`, before edges
// are considered (one channel): the largest channel difference of the compared values
// (HDR compressed), for normals the angle in degrees (180 where one of them has none, 0
// where neither has). What a reference's filter allowance is made of (references.h).
Image pixel_differences(Metric metric, const Image& image, const Image& reference);

// Compares `image` (the submission's) with `reference` under `metric`: it fails when
// more than allowed_failing_pixels() pixels are over fail_threshold (at the reference's
// edges, measured from the range of its 3x3 neighbourhood: compare.cpp says why), when one pixel
// differs by more than hard_fail, when the mean error over the covered pixels is over
// max_mean_error, or when the image holds NaN/Inf. `background`: the reference's, when
// already found (reference_background); otherwise it is found here. `allowance`: the
// reference's filter allowance (pixel_differences units, one channel) where it has one:
// each pixel's difference is counted less that much (at least 0).
Comparison compare_images(Metric metric, const Tolerance& tolerance, const Image& image, const Image& reference,
                          const Background* background = nullptr, const Image* allowance = nullptr);

// Lab 7's work check on one frame's counted work (render/light_volumes.h): it fails when
// the fragments shaded exceed the volumes' own screen coverage by more than fail_threshold
// (a share of it), when the full-screen loop's work over them is under min_speedup, or
// when `image_passed` is false: a wrong image gets no credit for speed (`image_check`
// names that check). The diff is black, `width` x `height`.
Comparison compare_work(const Tolerance& tolerance, const LightVolumeWork& work, bool image_passed,
                        const std::string& image_check, int width, int height);

// Lab 7's evidence (render/light_volumes.h VolumeEvidence), for naming its mistakes
// (diagnosis.h): a lab 7 frame's HDR check carries it after its tiles' signature
// (lab_verdict.cpp). Three shares of the lights measured, each as kSignatureCap x
// min(share, 1), repeated kEvidenceWidth times:
//   size:  |missing - extra| / footprint, a volume centred on its light but of another size
//          (its radius halved, doubled, a light's range for its radius, a full-screen quad);
//   place: 2 min(missing, extra) / footprint, a volume of about the right size elsewhere;
//   state: shaded_wrong / must_shade, plus 1 where the state replaces rather than adds: the
//          faces and depth test shade a pixel twice or not at all, or blending is off.
// Repeated, a scene's evidence weighs about as much as one of its images' 48 tiles would when
// they all fail (measured: instructors.md, Naming the mistake). Empty without evidence.
constexpr int kEvidenceWidth = 48;
std::vector<float> volume_evidence_signature(const VolumeEvidence& evidence);
// The evidence in words, for the worst light measured ("light 7's volume ... too small"),
// numbered from 1 as the scene lists its lights (like the worst pixel's description), or ""
// when the volumes and their state are right.
std::string describe_volume_evidence(const VolumeEvidence& evidence);
// The same evidence as parts of lab 7 that naming weighs as it weighs the probes'
// (diagnosis.h, kPassProbeWeight): "light_volume.vert, radius" where a light's volume drawn
// alone is too small or too large (over 2 % of its sphere's pixels), "light_volume.vert,
// placement" where it lies elsewhere, "light_volume.vert, state" where the state gives the
// surface pixels inside a sphere no fragment or two (over 2 % of them), "light_volume.vert,
// blend" for blend(off).
std::set<std::string> volume_evidence_parts(const VolumeEvidence& evidence);
// The part a failed work check adds where its image passed: the work is over the limit.
constexpr const char* kWorkPart = "light_volume.vert, work";
// What every part above starts with: parts a run without the counts cannot know (WebGL2 counts
// no samples: the browser's check), which naming then leaves out of the comparison.
constexpr const char* kVolumeEvidencePrefix = "light_volume.vert, ";

// The image as the report shows it (RGB, [0,1]): G-buffer vectors as (v+1)/2,
// positions over the reference's bounds, HDR through Reinhard and gamma 2.2,
// NaN/Inf pixels magenta. `reference` supplies the bounds for positions.
Image display_image(Metric metric, const Image& image, const Image& reference);

constexpr int kSignatureColumns = 8, kSignatureRows = 6;
constexpr float kSignatureCap = 4.0f;

// Factor the report's diff images scale |a - b| by before the colour map.
constexpr float kDiffScale = 16.0f;

}  // namespace kit::grade
