#include "verdict/compare.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <limits>
#include <utility>
#include <vector>

#include "render/renderer.h"

namespace kit::grade {

namespace {

// Below this length a G-buffer normal counts as "nothing written" (background).
constexpr float kMinNormalLength = 1e-3f;
constexpr double kRadiansToDegrees = 57.29577951308232;
// Display gamma for HDR and the report's other linear images.
constexpr float kDisplayGamma = 2.2f;

// The statistics of idiff and OpenImageIO's ImageBufAlgo::compare over the first
// `channels` channels, with its definitions and its summation order (pixels in rows,
// sums in double, in batches of 4096 pixels), computed in one pass over the floats:
// through ImageBuf's iterators the two compares of a check were a sixth of the
// comparison's time. The images hold no NaN or Inf here (compared).
struct ChannelStats {
  double mean_error = 0.0;  // mean |a - b| over every value
  double psnr = 0.0;        // 20 log10(largest value, at least 1, / RMS error): inf when identical
  double max_error = 0.0;   // the largest |a - b|, and where it is first
  int max_x = 0, max_y = 0;
  size_t failing = 0;       // pixels with a channel over `threshold`
};

// With `largest`, also each pixel's largest channel difference (the diff image's input).
ChannelStats channel_stats(const Image& a, const Image& b, int channels, float threshold, Image* largest = nullptr) {
  constexpr size_t kBatchPixels = 4096;
  ChannelStats s;
  const size_t stride = static_cast<size_t>(a.channels);
  const size_t pixels = static_cast<size_t>(a.width) * static_cast<size_t>(a.height);
  double total = 0.0, total_squares = 0.0;
  float largest_value = 1.0f;
  for (size_t start = 0; start < pixels; start += kBatchPixels) {
    double batch = 0.0, batch_squares = 0.0;
    for (size_t p = start; p < std::min(pixels, start + kBatchPixels); ++p) {
      const float* pa = a.pixels.data() + p * stride;
      const float* pb = b.pixels.data() + p * stride;
      bool failed = false;
      float pixel_largest = 0.0f;
      for (int c = 0; c < channels; ++c) {
        largest_value = std::max(largest_value, std::max(pa[c], pb[c]));
        const float difference = std::fabs(pa[c] - pb[c]);
        pixel_largest = std::max(pixel_largest, difference);
        const double f = difference;
        batch += f;
        batch_squares += f * f;
        if (f > s.max_error) {
          s.max_error = f;
          s.max_x = static_cast<int>(p % static_cast<size_t>(a.width));
          s.max_y = static_cast<int>(p / static_cast<size_t>(a.width));
        }
        failed = failed || f > threshold;
      }
      s.failing += failed;
      if (largest) largest->pixels[p] = pixel_largest;
    }
    total += batch;
    total_squares += batch_squares;
  }
  const double values = static_cast<double>(pixels) * channels;
  s.mean_error = total / values;
  s.psnr = 20.0 * std::log10(largest_value / std::sqrt(total_squares / values));
  return s;
}


// ---- Edges: where a conformant renderer may put the reference's values one pixel over ----
// GL fixes what a pixel shows only up to the implementation's choices: sub-pixel precision
// and rounding where a triangle's edge crosses a pixel centre, which mip level and filter
// weights a texture lookup uses (derivatives are computed per 2x2 quad, with a precision of
// the implementation's own), the precision of interpolated attributes. Where the reference
// changes little from pixel to pixel, those choices move a value by a little; at an edge
// (a silhouette, a texel boundary of a magnified texture, a shadow or cone border) they can
// swap it for its neighbour's. llvmpipe, softpipe and GPUs do differ there.
//
// So at an edge pixel of the reference (its 3x3 neighbourhood spans more than the
// tolerance's fail_threshold in a channel) the error is the distance to the nearest blend
// of the reference's value there with one of its neighbours' (distance_to_neighbourhood);
// elsewhere it is the plain difference. A mistake that moves an edge by more than a
// pixel, or that changes a surface's inside, still counts in full. The cost: a mistake
// that changes only edge pixels, within their neighbours' values, or moves the image by
// less than a pixel, is not seen by such a comparison; the checks that catch those compare
// a submission's render with another of its own (Metric::Same) or show the mistake inside
// a surface.
constexpr int kEdgeRadius = 1;  // the neighbourhood: (2 kEdgeRadius + 1)^2 pixels

// Calls visit(qx, qy) for every pixel of the neighbourhood of (x, y) in `image`, (x, y)
// itself included; at the image's border the nearest pixel stands in for one outside.
template <typename Visit>
void for_each_neighbour(const Image& image, int x, int y, Visit visit) {
  for (int dy = -kEdgeRadius; dy <= kEdgeRadius; ++dy)
    for (int dx = -kEdgeRadius; dx <= kEdgeRadius; ++dx)
      visit(std::clamp(x + dx, 0, image.width - 1), std::clamp(y + dy, 0, image.height - 1));
}

// True where the reference's neighbourhood of (x, y) spans more than `threshold` in one of
// its first `channels` (at most 4) channels.
bool is_edge(const Image& reference, int x, int y, int channels, float threshold) {
  std::array<float, 4> lo{}, hi{};
  for (int c = 0; c < channels; ++c) lo[c] = hi[c] = reference.at(x, y, c);
  for_each_neighbour(reference, x, y, [&](int qx, int qy) {
    for (int c = 0; c < channels; ++c) {
      lo[c] = std::min(lo[c], reference.at(qx, qy, c));
      hi[c] = std::max(hi[c], reference.at(qx, qy, c));
    }
  });
  for (int c = 0; c < channels; ++c)
    if (hi[c] - lo[c] > threshold) return true;
  return false;
}

// How far the submission's value at (x, y) is from what the reference shows there with its
// edge moved by up to a pixel: a blend, with one weight for every channel, of the
// reference's value at (x, y) and that of one of its neighbours (a silhouette one pixel
// over is the neighbour itself; a texel boundary filtered another way, a blend). The
// smallest, over the neighbours, of the largest channel's distance to that segment. Not
// a channel-by-channel range: a surface lit differently at a texture's edges (a normal map
// ignored, darkening the mortar between bricks) is no blend of the mortar and the brick.
float distance_to_neighbourhood(const Image& image, const Image& reference, int x, int y, int channels) {
  float nearest = std::numeric_limits<float>::max();
  for_each_neighbour(reference, x, y, [&](int qx, int qy) {
    // The weight t in [0, 1] of the neighbour that fits best (least squares), then the
    // largest channel's distance from the blend.
    double along = 0.0, length2 = 0.0;
    for (int c = 0; c < channels; ++c) {
      const double d = reference.at(qx, qy, c) - reference.at(x, y, c);
      along += (image.at(x, y, c) - reference.at(x, y, c)) * d;
      length2 += d * d;
    }
    const double t = length2 > 0.0 ? std::clamp(along / length2, 0.0, 1.0) : 0.0;
    float largest = 0.0f;
    for (int c = 0; c < channels; ++c) {
      const double blend = reference.at(x, y, c) + t * (reference.at(qx, qy, c) - reference.at(x, y, c));
      largest = std::max(largest, static_cast<float>(std::fabs(image.at(x, y, c) - blend)));
    }
    nearest = std::min(nearest, largest);
  });
  return nearest;
}

// The pixel at (x, y) as "(a, b, c)", its first `channels` channels (all: -1).
std::string pixel_text(const Image& image, int x = 0, int y = 0, int channels = -1) {
  std::string out = "(";
  const int n = channels < 0 ? image.channels : std::min(channels, image.channels);
  for (int c = 0; c < n; ++c) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%s%.3g", c ? ", " : "", image.pixels.empty() ? 0.0 : image.at(x, y, c));
    out += buf;
  }
  return out + ")";
}

// What the worst pixel of a failed comparison holds, yours and the reference's, in the
// metric's words; for a G-buffer attachment, the channel that differs most there.
std::string worst_pixel_text(Metric metric, const Image& image, const Image& reference, int x, int y) {
  static const char* const kChannels[][4] = {{"r", "g", "b", "a"},  {"r", "g", "b", "a"}, {"x", "y", "z", "w"},
                                             {"x", "y", "z", "w"},  {"r", "g", "b", "a"},
                                             {"metallic", "roughness", "(unused)", "coverage mask"}};
  const char* what = metric == Metric::Ldr        ? "display value"
                     : metric == Metric::Hdr      ? "HDR radiance"
                     : metric == Metric::Position ? "world position (m)"
                     : metric == Metric::Normal   ? "normal"
                     : metric == Metric::Albedo   ? "albedo"
                                                  : "material";
  const int channels = metric == Metric::Material ? 4 : 3;
  char head[96];
  std::snprintf(head, sizeof head, "the worst pixel, (%d, %d): your %s ", x, y, what);
  std::string out = head + pixel_text(image, x, y, channels) + ", the reference's " + pixel_text(reference, x, y, channels);
  if (metric == Metric::Position || metric == Metric::Albedo || metric == Metric::Material) {
    int worst = 0;
    for (int c = 1; c < channels && c < image.channels; ++c)
      if (std::fabs(image.at(x, y, c) - reference.at(x, y, c)) > std::fabs(image.at(x, y, worst) - reference.at(x, y, worst)))
        worst = c;
    char tail[128];
    std::snprintf(tail, sizeof tail, ": %s is %.3g where %.3g is expected", kChannels[static_cast<int>(metric)][worst],
                  static_cast<double>(image.at(x, y, worst)), static_cast<double>(reference.at(x, y, worst)));
    out += tail;
  }
  return out;
}

// The diff's colour map: OpenImageIO's "inferno" (matplotlib's map, as the linear values
// OpenImageIO interpolates between) at its 17 evenly spaced knots. Written here so that
// grading never loads OpenImageIO (openimageio_formats.h); test_grader checks the
// colours against OpenImageIO's own color_map.
constexpr int kInfernoKnots = 17;
constexpr float kInferno[kInfernoKnots][3] = {
    {0.000113f, 0.000036f, 0.001073f},
    {0.003275f, 0.002178f, 0.017634f},
    {0.015183f, 0.003697f, 0.068760f},
    {0.046307f, 0.002834f, 0.130327f},
    {0.095494f, 0.005137f, 0.154432f},
    {0.163601f, 0.009920f, 0.156097f},
    {0.253890f, 0.016282f, 0.143715f},
    {0.367418f, 0.024893f, 0.119982f},
    {0.500495f, 0.038279f, 0.089117f},
    {0.642469f, 0.061553f, 0.057555f},
    {0.776190f, 0.102517f, 0.031141f},
    {0.883568f, 0.169990f, 0.012559f},
    {0.951614f, 0.271639f, 0.002704f},
    {0.972636f, 0.413571f, 0.005451f},
    {0.943272f, 0.599923f, 0.035112f},
    {0.884900f, 0.822282f, 0.140466f},
    {0.973729f, 0.996282f, 0.373522f},
};

// One channel of per-pixel error -> RGB through the inferno map, scaled by kDiffScale.
Image colour_mapped(const Image& error) {
  Image out(error.width, error.height, 3);
  for (size_t i = 0; i < error.pixels.size(); ++i) {
    const float t = std::min(std::max(error.pixels[i] * kDiffScale, 0.0f), 1.0f) * (kInfernoKnots - 1);
    const int knot = std::min(static_cast<int>(t), kInfernoKnots - 2);
    const float f = t - static_cast<float>(knot);
    for (int c = 0; c < 3; ++c) {
      const float lo = kInferno[knot][c], hi = kInferno[knot + 1][c];
      out.pixels[i * 3 + static_cast<size_t>(c)] = lo + (hi - lo) * f;
    }
  }
  return out;
}

struct NormalStats {
  double max_angle = 0.0, sum_angle = 0.0;
  int max_x = 0, max_y = 0;
  size_t failing = 0, covered = 0;
  size_t not_unit = 0;  // failing because |n| differs from the reference's length, not the angle
  size_t edges = 0;     // failing pixels that a neighbour of the reference matches (is_edge)
  size_t filtered = 0;  // failing pixels that the filter allowance brings under the threshold
  Image error;  // per-pixel max |a - b| over xyz, for the diff image
  Image angle;  // per-pixel angle in degrees (180 where only one image has a normal)
};

// How the normal a(x, y) compares with b(bx, by): the angle in degrees (180 where only
// one of them is written; -1 where neither is) and whether their lengths differ by more
// than the tolerance.
struct NormalMatch {
  double angle = -1.0;
  bool length_off = false;
};
NormalMatch match_normal(const Image& a, int x, int y, const Image& b, int bx, int by, const Tolerance& tol) {
  float la = 0.0f, lb = 0.0f, dot = 0.0f;
  for (int c = 0; c < 3; ++c) {
    la += a.at(x, y, c) * a.at(x, y, c);
    lb += b.at(bx, by, c) * b.at(bx, by, c);
    dot += a.at(x, y, c) * b.at(bx, by, c);
  }
  la = std::sqrt(la);
  lb = std::sqrt(lb);
  NormalMatch m;
  if (la < kMinNormalLength && lb < kMinNormalLength) return m;  // background in both
  if (la < kMinNormalLength || lb < kMinNormalLength) {
    m.angle = 180.0;  // a normal written where there is none, or missing where there is one
    return m;
  }
  const double cosine = std::clamp(static_cast<double>(dot) / (la * lb), -1.0, 1.0);
  m.angle = std::acos(cosine) * kRadiansToDegrees;
  m.length_off = std::fabs(la - lb) > tol.length_tolerance;
  return m;
}

bool fails(const NormalMatch& m, const Tolerance& tol) { return m.angle > tol.fail_threshold || m.length_off; }

// An edge of the reference's normals (is_edge for directions): its neighbourhood holds
// normals more than fail_threshold apart, or both written and unwritten pixels.
bool is_normal_edge(const Image& b, int x, int y, const Tolerance& tol) {
  bool edge = false;
  for_each_neighbour(b, x, y, [&](int qx, int qy) {
    edge = edge || match_normal(b, x, y, b, qx, qy, tol).angle > tol.fail_threshold;
  });
  return edge;
}

NormalStats compare_normals(const Image& a, const Image& b, const Tolerance& tol, const Image* allowance) {
  NormalStats s;
  s.error = Image(a.width, a.height, 1);
  s.angle = Image(a.width, a.height, 1);
  for (int y = 0; y < a.height; ++y) {
    for (int x = 0; x < a.width; ++x) {
      NormalMatch m = match_normal(a, x, y, b, x, y, tol);
      int mx = x, my = y;  // the reference pixel it is compared with
      if ((m.angle > 0.0 || m.length_off) && is_normal_edge(b, x, y, tol)) {
        // At an edge of the reference: its best match in the neighbourhood (see is_edge),
        // a passing one before a failing one, then the smaller angle.
        const bool direct_fails = fails(m, tol);
        for_each_neighbour(b, x, y, [&](int qx, int qy) {
          NormalMatch q = match_normal(a, x, y, b, qx, qy, tol);
          if (q.angle < 0.0) q.angle = 0.0;  // unwritten in both: the reference's background one pixel over
          const bool better = fails(q, tol) != fails(m, tol) ? !fails(q, tol) : q.angle < m.angle;
          if (better) {
            m = q;
            mx = qx;
            my = qy;
          }
        });
        if (direct_fails && !fails(m, tol)) ++s.edges;
      }
      float diff = 0.0f;
      for (int c = 0; c < 3; ++c) diff = std::max(diff, std::fabs(a.at(x, y, c) - b.at(mx, my, c)));
      s.error.at(x, y, 0) = diff;
      if (m.angle < 0.0) continue;  // background in both
      double angle = m.angle;
      if (allowance) {
        const bool over = fails(m, tol);
        angle = std::max(0.0, angle - static_cast<double>(allowance->at(x, y, 0)));
        m.angle = angle;
        s.filtered += over && !fails(m, tol);
      }
      const bool pixel_fails = fails(m, tol);
      if (m.length_off) ++s.not_unit;
      s.angle.at(x, y, 0) = static_cast<float>(angle);
      ++s.covered;
      s.sum_angle += angle;
      if (pixel_fails) ++s.failing;
      if (angle > s.max_angle) {
        s.max_angle = angle;
        s.max_x = x;
        s.max_y = y;
      }
    }
  }
  return s;
}

// The reference's background: its most common pixel value (the clear colour of a
// display image, zeros in a G-buffer attachment); the smallest such value on a tie.
// When the top-left pixel's value covers more than half of the image, it is the one
// (a strict majority has no tie), found in one pass. Otherwise equal pixels are counted
// in an open-addressing table (a std::map of them took 3 % of a whole grading run's
// CPU, sorting the pixels 7 % of the grading process's). The copies compared here hold
// no NaN (compared zeroes them), so == is an equivalence; -0 hashes as +0, which
// it equals.
Background most_common_pixel(const Image& image) {
  using Pixel = std::array<float, 4>;
  const size_t count = static_cast<size_t>(image.width) * static_cast<size_t>(image.height);
  auto pixel = [&](size_t i) {
    Pixel v{0.0f, 0.0f, 0.0f, 0.0f};
    for (int c = 0; c < std::min(image.channels, 4); ++c)
      v[static_cast<size_t>(c)] = image.pixels[i * static_cast<size_t>(image.channels) + static_cast<size_t>(c)];
    return v;
  };
  if (count == 0) return {0.0f, 0.0f, 0.0f, 0.0f};
  const Pixel corner = pixel(0);
  size_t corner_count = 0;
  for (size_t i = 0; i < count; ++i) corner_count += pixel(i) == corner;
  if (2 * corner_count > count) return corner;

  // Each slot holds a pixel's index + 1 (0: empty) and its value's count. The table is
  // kept between calls (a thread's own), its used slots emptied after: allocating and
  // clearing 3 MB for each reference was most of this function's time.
  size_t capacity = 1;
  while (capacity < 2 * count) capacity <<= 1;  // at most half full: short probes
  thread_local std::vector<uint32_t> first_pixel, counts;
  thread_local std::vector<size_t> used;
  if (first_pixel.size() < capacity) {
    first_pixel.assign(capacity, 0);
    counts.assign(capacity, 0);
  }
  auto hash = [](const Pixel& v) {
    uint64_t h = 0x9e3779b97f4a7c15ull;
    for (float f : v) {
      uint32_t bits = 0;
      const float positive_zero = f == 0.0f ? 0.0f : f;
      std::memcpy(&bits, &positive_zero, sizeof bits);
      h = (h ^ bits) * 0xff51afd7ed558ccdull;
      h ^= h >> 29;
    }
    return static_cast<size_t>(h);
  };
  used.clear();
  for (size_t i = 0; i < count; ++i) {
    const Pixel v = pixel(i);
    size_t slot = hash(v) & (capacity - 1);
    while (first_pixel[slot] != 0 && !(pixel(first_pixel[slot] - 1) == v)) slot = (slot + 1) & (capacity - 1);
    if (first_pixel[slot] == 0) {
      first_pixel[slot] = static_cast<uint32_t>(i + 1);
      used.push_back(slot);
    }
    ++counts[slot];
  }
  size_t best = used.front();
  for (size_t slot : used)
    if (counts[slot] > counts[best] ||
        (counts[slot] == counts[best] && pixel(first_pixel[slot] - 1) < pixel(first_pixel[best] - 1)))
      best = slot;
  const Pixel value = pixel(first_pixel[best] - 1);
  for (size_t slot : used) first_pixel[slot] = counts[slot] = 0;
  return value;
}

bool shows(const Image& image, int x, int y, const std::array<float, 4>& background) {
  for (int c = 0; c < std::min(image.channels, 4); ++c)
    if (image.at(x, y, c) != background[static_cast<size_t>(c)]) return true;
  return false;
}

std::string format(const char* fmt, double a, double b = 0.0, double c = 0.0) {
  char buf[200];
  std::snprintf(buf, sizeof buf, fmt, a, b, c);
  return buf;
}

std::string psnr_text(double psnr) { return std::isfinite(psnr) ? format("%.1f dB", psnr) : "inf (identical)"; }

// An image as it is compared under `metric`: NaN and Inf replaced by 0, so the statistics
// stay numbers (the non-finite pixels are counted and fail the check on their own), and
// HDR compressed to c / (1 + |c|): a tolerance of t is then absolute near 0 and relative
// (about t (1 + c)^2) for bright pixels, which matches how far a tone-mapped display
// would show the difference. `image` itself where that changes nothing (a finite image
// under any other metric, most of them): copying two images a check was a tenth of the
// grading process's time. Otherwise the copy, made in `storage`. `finite`: the caller has
// counted the image's non-finite pixels and found none.
const Image& compared(Metric metric, const Image& image, Image& storage, bool finite = false) {
  const bool hdr = metric == Metric::Hdr;
  if (!hdr && (finite || !first_non_finite(image))) return image;
  storage = image;
  const size_t alpha = image.channels == 4 ? 3 : 4;  // alpha as it is; no index % 4 is 4
  for (size_t i = 0; i < storage.pixels.size(); ++i) {
    float& v = storage.pixels[i];
    if (!std::isfinite(v)) v = 0.0f;
    if (hdr && i % 4 != alpha) v = v / (1.0f + std::fabs(v));
  }
  return storage;
}

}  // namespace

double largest_possible_difference(Metric metric) {
  switch (metric) {
    case Metric::Ldr:
    case Metric::Albedo:
    case Metric::Changes:
    case Metric::Same: return 1.0;  // RGBA8: values in [0, 1]
    case Metric::Work: return 0.0;  // no pixels compared
    case Metric::Hdr: return 2.0;      // c / (1 + |c|) lies in (-1, 1)
    case Metric::Normal: return 180.0;
    case Metric::Position:
    case Metric::Material: return 2.0 * 65504.0;  // RGBA16F
  }
  return 0.0;
}

size_t allowed_failing_pixels(const Tolerance& tolerance, size_t pixels) {
  return static_cast<size_t>(std::floor(tolerance.fail_percent / 100.0 * static_cast<double>(pixels) + 1e-9));
}

bool is_uniform(const Image& image) {
  // Pixel by pixel: an index % channels for every value was most of a report's writing time.
  const size_t n = static_cast<size_t>(image.channels);
  if (n == 0) return true;
  for (size_t p = n; p + n <= image.pixels.size(); p += n)
    for (size_t c = 0; c < n; ++c)
      if (image.pixels[p + c] != image.pixels[c]) return false;
  return true;
}

Background reference_background(Metric metric, const Image& reference) {
  Image storage;
  return most_common_pixel(compared(metric, reference, storage));
}

Image pixel_differences(Metric metric, const Image& image, const Image& reference) {
  Image storage_a, storage_b;
  const Image& a = compared(metric, image, storage_a);
  const Image& b = compared(metric, reference, storage_b);
  if (metric == Metric::Normal) {
    Tolerance any;  // the angle alone is wanted: the length test's tolerance does not matter
    Image out(a.width, a.height, 1);
    for (int y = 0; y < a.height; ++y)
      for (int x = 0; x < a.width; ++x)
        out.at(x, y, 0) = static_cast<float>(std::max(0.0, match_normal(a, x, y, b, x, y, any).angle));
    return out;
  }
  Image out(a.width, a.height, 1);
  channel_stats(a, b, a.channels, 0.0f, &out);
  return out;
}

namespace {

// compare_images' steps, in the order it takes them.

// Images of different sizes: nothing compared, and a note that says why. The framework
// fixes every size (the grading size, lab 6's maps their own), so sizes that differ mean
// references made by another version of the kit.
Comparison size_mismatch(const Image& image, const Image& reference) {
  Comparison r;
  auto size = [](const Image& i) {
    return std::to_string(i.width) + "x" + std::to_string(i.height) + " with " + std::to_string(i.channels) +
           " channels";
  };
  r.note = "the image is " + size(image) + ", the reference " + size(reference) +
           ": nothing was compared (the renderer's sizes changed since the references were made: "
           "kit-grade --check-references says which; --update-references renders them again)";
  r.summary = r.note;
  r.diff = Image(std::max(image.width, 1), std::max(image.height, 1), 3);  // blank: the report still has one
  return r;
}

// Each pixel's error as the comparison counts it.
struct PixelErrors {
  Image error;         // for the diff image
  Image normal_angle;  // the normals' angles, where they are compared
};

// Metric::Normal, pixel by pixel (compare_normals): r's largest angle and where, its mean,
// the failing, edge and filter counts.
PixelErrors compare_normal_pixels(const Image& a, const Image& b, const Tolerance& tol, const Image* allowance,
                                  double pixels, Comparison& r) {
  NormalStats s = compare_normals(a, b, tol, allowance);
  r.max_error = s.max_angle;
  r.max_x = s.max_x;
  r.max_y = s.max_y;
  r.mean_error = s.covered ? s.sum_angle / static_cast<double>(s.covered) : 0.0;
  r.failing_pixels = s.failing;
  r.edge_pixels = s.edges;
  r.filter_pixels = s.filtered;
  r.psnr = channel_stats(a, b, 3, 1.0f).psnr;  // of the xyz values
  PixelErrors out;
  out.error = std::move(s.error);
  out.normal_angle = std::move(s.angle);
  // A normal can point the right way and still be wrong (not unit length): say so.
  if (s.not_unit > 0)
    r.note = format("%.2f%% of the normals differ in length from the reference's by more than %.3g "
                    "(normalise the normal)", 100.0 * static_cast<double>(s.not_unit) / pixels, tol.length_tolerance);
  return out;
}

// Every other metric, pixel by pixel: each pixel's largest channel difference, as counted
// (the diff image's input); r's largest error and where, the means, the failing, edge and
// filter counts.
Image compare_channel_pixels(Metric metric, const Image& a, const Image& b, const Tolerance& tol,
                             const Image* allowance, Comparison& r) {
  const float threshold = static_cast<float>(tol.fail_threshold);
  Image error(a.width, a.height, 1);
  const ChannelStats cs = channel_stats(a, b, a.channels, threshold, &error);
  r.mean_error = cs.mean_error;
  r.psnr = cs.psnr;
  // The counted error: at the reference's edges, the distance to the nearest blend with a
  // neighbour (distance_to_neighbourhood). Two renders of the submission itself (Changes,
  // Same) come from one machine: every pixel counts as it is, edges included.
  const bool edges_may_move = !compares_own_renders(metric);
  r.max_error = 0.0;
  for (int y = 0; y < a.height; ++y)
    for (int x = 0; x < a.width; ++x) {
      float& e = error.at(x, y, 0);
      if (edges_may_move && e > 0.0f && is_edge(b, x, y, a.channels, threshold)) {
        const float shifted = distance_to_neighbourhood(a, b, x, y, a.channels);
        if (e > threshold && shifted <= threshold) ++r.edge_pixels;
        e = shifted;
      }
      if (allowance && e > 0.0f) {
        const float allowed = std::max(0.0f, e - allowance->at(x, y, 0));
        if (e > threshold && allowed <= threshold) ++r.filter_pixels;
        e = allowed;
      }
      r.failing_pixels += e > threshold;
      if (e > r.max_error) {
        r.max_error = e;
        r.max_x = x;
        r.max_y = y;
      }
    }
  return error;
}

// The mean of each pixel's error (its largest channel difference; for normals the
// angle) over the covered pixels: those where the reference or the submission shows
// something other than the reference's background. A faint difference spread over
// many pixels raises it while staying under every per-pixel threshold. Each pixel
// counts at most fail_threshold: pixels over it are the failing share's business, so
// the few it allows (a flipped silhouette pixel) cannot fail this criterion instead.
void add_covered_mean_error(const Image& a, const Image& b, const Image& pixel_error, const Tolerance& tol,
                            const Background* background, Comparison& r) {
  const Background found = background ? *background : most_common_pixel(b);
  const double cap = tol.fail_threshold;
  double sum = 0.0;
  for (int y = 0; y < a.height; ++y)
    for (int x = 0; x < a.width; ++x)
      if (shows(a, x, y, found) || shows(b, x, y, found)) {
        ++r.covered_pixels;
        sum += std::min(static_cast<double>(pixel_error.at(x, y, 0)), cap);
      }
  r.covered_mean_error = r.covered_pixels ? sum / static_cast<double>(r.covered_pixels) : 0.0;
}

// Where the error lies, coarsely (Comparison::signature): each tile's mean of the pixels'
// errors over fail_threshold, each capped at kSignatureCap.
std::vector<float> error_signature(const Image& pixel_error, const Tolerance& tol) {
  std::vector<float> signature(static_cast<size_t>(kSignatureColumns * kSignatureRows), 0.0f);
  std::vector<int> counts(signature.size(), 0);
  const int width = pixel_error.width, height = pixel_error.height;
  const float scale = tol.fail_threshold > 0.0 ? static_cast<float>(1.0 / tol.fail_threshold) : 1.0f;
  std::vector<int> column_tile(static_cast<size_t>(width));  // two divisions a pixel were a tenth of this
  for (int x = 0; x < width; ++x) column_tile[static_cast<size_t>(x)] = x * kSignatureColumns / width;
  for (int y = 0; y < height; ++y) {
    const int row_tile = y * kSignatureRows / height * kSignatureColumns;
    for (int x = 0; x < width; ++x) {
      const size_t tile = static_cast<size_t>(row_tile + column_tile[static_cast<size_t>(x)]);
      signature[tile] += std::min(pixel_error.at(x, y, 0) * scale, kSignatureCap);
      ++counts[tile];
    }
  }
  for (size_t i = 0; i < counts.size(); ++i)
    if (counts[i]) signature[i] /= static_cast<float>(counts[i]);
  return signature;
}

// NaN/Inf pixels show at full scale in the diff (their compared copies were zeroed).
void mark_non_finite(const Image& image, Image& error) {
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x)
      for (int c = 0; c < image.channels; ++c)
        if (!std::isfinite(image.at(x, y, c))) error.at(x, y, 0) = 1.0f;
}

// Metric::Changes: enough pixels must change.
void judge_changes(const Tolerance& tol, Comparison& r) {
  r.passed = r.failing_percent >= tol.min_changed_percent;
  r.summary = format("%.2f%% of the pixels change by more than %.3g", r.failing_percent, tol.fail_threshold) +
              format(" (at least %.2f%% must); largest change %.3g", tol.min_changed_percent, r.max_error);
  if (!r.passed) r.note = "turning the effect on leaves the image (almost) as it was";
}

// Which of a comparison's criteria it meets.
struct Criteria {
  bool share_ok, hard_ok, mean_ok;
};

// The words of a verdict: every criterion with its number and its limit, pixel counts as
// integers, so the words never show a passing share beside a failing limit; those over
// their limit first.
std::string verdict_summary(Metric metric, const Tolerance& tol, const Comparison& r, size_t total, Criteria met) {
  const std::string unit = metric == Metric::Normal ? " degrees" : metric == Metric::Position ? " m" : "";
  const std::string share = std::to_string(r.failing_pixels) + " of " + std::to_string(total) +
                            format(" pixels (%.3f%%) differ by more than ", r.failing_percent) +
                            format("%.3g", tol.fail_threshold) + unit +
                            (metric == Metric::Normal ? " or in length" : "");
  const std::string allowed = std::to_string(r.allowed_failing_pixels) + format(" (%.2f%%)", tol.fail_percent);
  const std::string mean = format("the mean error over the %.0f covered pixels is %.3g", static_cast<double>(r.covered_pixels),
                                  r.covered_mean_error) + unit;
  const std::string largest = format("the largest difference is %.3g", r.max_error) + unit +
                              format(" at (%.0f, %.0f)", r.max_x, r.max_y);
  const bool hard_applies = tol.hard_fail < largest_possible_difference(metric);
  std::vector<std::string> over;
  if (!met.share_ok) over.push_back(share + ", more than the " + allowed + " allowed");
  if (!met.mean_ok)
    over.push_back(mean + format(", over the limit of %.3g", tol.max_mean_error) + unit +
                   (met.share_ok ? " (a faint difference spread over many pixels)" : ""));
  if (!met.hard_ok)
    over.push_back(largest + format(", over the limit of %.3g", tol.hard_fail) + unit +
                   (metric == Metric::Hdr ? " (compressed values lie in (-1, 1): only a pixel whose sign differs from "
                                            "the reference's gets there; negative radiance?)"
                                          : ""));
  std::string numbers = share + " (at most " + allowed + " may); " + mean +
                        format(" (at most %.3g)", tol.max_mean_error) + "; " + largest +
                        (hard_applies ? format(" (at most %.3g)", tol.hard_fail) : std::string()) +
                        (metric == Metric::Normal ? format("; mean angle %.3g degrees", r.mean_error)
                                                  : format("; mean error over all pixels %.3g", r.mean_error)) +
                        "; PSNR " + psnr_text(r.psnr) +
                        (r.edge_pixels ? "; " + std::to_string(r.edge_pixels) +
                                             " pixels at edges of the reference are within its values one pixel over"
                                       : std::string()) +
                        (r.filter_pixels ? "; " + std::to_string(r.filter_pixels) +
                                               " pixels are within the reference's own spread under GPU-like texture filtering"
                                         : std::string());
  if (over.empty()) return numbers;
  std::string summary = "Over the limit: ";
  for (size_t i = 0; i < over.size(); ++i) summary += (i ? "; " : "") + over[i];
  summary += ". All numbers: " + numbers;
  return summary;
}

// Every metric but Changes: the verdict against the tolerance's three limits and NaN/Inf,
// its words, and for a failure its worst pixel and what to look at.
void judge_against_tolerance(Metric metric, const Tolerance& tol, const Image& image, const Image& reference,
                             double pixels, Comparison& r) {
  const size_t total = static_cast<size_t>(image.width) * static_cast<size_t>(image.height);
  r.allowed_failing_pixels = allowed_failing_pixels(tol, total);
  const Criteria met{r.failing_pixels <= r.allowed_failing_pixels, r.max_error <= tol.hard_fail,
                     r.covered_mean_error <= tol.max_mean_error};
  r.passed = r.non_finite == 0 && met.share_ok && met.hard_ok && met.mean_ok;
  r.summary = verdict_summary(metric, tol, r, total, met);
  r.width = image.width;
  r.height = image.height;
  if (!r.passed && r.max_x >= 0 && r.max_x < image.width && r.max_y >= 0 && r.max_y < image.height)
    r.worst_pixel = worst_pixel_text(metric, image, reference, r.max_x, r.max_y);
  if (r.non_finite > 0) {
    r.note = std::to_string(r.non_finite) + format(" pixels (%.1f%%) are NaN or Inf: ", 100.0 * static_cast<double>(r.non_finite) / pixels) +
             kNonFiniteAdvice;
  } else if (!r.passed && is_uniform(image) && !is_uniform(reference)) {
    r.note = "every pixel is " + pixel_text(image) + ": does the shader write its output?";
  }
}

}  // namespace

Comparison compare_images(Metric metric, const Tolerance& tol, const Image& image, const Image& reference,
                          const Background* background, const Image* allowance) {
  if (allowance && (allowance->width != reference.width || allowance->height != reference.height))
    allowance = nullptr;  // made for another size: the references' check (manifest_differences) says so
  if (image.width != reference.width || image.height != reference.height || image.channels != reference.channels)
    return size_mismatch(image, reference);
  Comparison r;
  r.non_finite = count_non_finite(image);
  Image storage_a, storage_b;
  const Image& a = compared(metric, image, storage_a, r.non_finite == 0);
  const Image& b = compared(metric, reference, storage_b);
  const double pixels = static_cast<double>(image.width) * image.height;
  PixelErrors errors;
  if (metric == Metric::Normal)
    errors = compare_normal_pixels(a, b, tol, allowance, pixels, r);
  else
    errors.error = compare_channel_pixels(metric, a, b, tol, allowance, r);
  // What the mean over covered pixels and the signature average: the angle for normals,
  // else the counted error (the diff image's input until non-finite pixels mark it below).
  const Image& pixel_error = metric == Metric::Normal ? errors.normal_angle : errors.error;
  r.failing_percent = 100.0 * static_cast<double>(r.failing_pixels) / pixels;
  if (metric != Metric::Changes) add_covered_mean_error(a, b, pixel_error, tol, background, r);
  if (metric != Metric::Changes && metric != Metric::Same) r.signature = error_signature(pixel_error, tol);
  if (r.non_finite > 0) mark_non_finite(image, errors.error);
  r.diff = colour_mapped(errors.error);
  if (metric == Metric::Changes)
    judge_changes(tol, r);
  else
    judge_against_tolerance(metric, tol, image, reference, pixels, r);
  return r;
}

Comparison compare_work(const Tolerance& tol, const LightVolumeWork& work, bool image_passed,
                        const std::string& image_check, int width, int height) {
  Comparison r;
  r.diff = Image(width, height, 3);
  const double loop = static_cast<double>(work.surface_pixels) * work.volume_lights;
  const double allowed = static_cast<double>(work.volume_coverage) * (1.0 + tol.fail_threshold);
  const double speedup = work.speedup();
  const bool within_coverage = static_cast<double>(work.shaded_fragments) <= allowed;
  const bool fast_enough = speedup >= tol.min_speedup;
  r.passed = image_passed && within_coverage && fast_enough;
  r.max_error = static_cast<double>(work.shaded_fragments);
  char text[640];
  std::snprintf(text, sizeof text,
                "%.0f fragments shaded for %d light volumes; the framework's volumes under cull(front) "
                "depth(greater_equal) shade %.0f (at most %.0f may be shaded, %.3g%% over); the full-screen loop "
                "shades %.0f (%.0f surface pixels x %d lights): "
                "%.1fx fewer (at least %.3gx)",
                static_cast<double>(work.shaded_fragments), work.volume_lights, static_cast<double>(work.volume_coverage),
                std::floor(allowed), 100.0 * tol.fail_threshold, loop, static_cast<double>(work.surface_pixels),
                work.volume_lights, speedup, tol.min_speedup);
  r.summary = text;
  if (!image_passed)
    r.note = "the image of this frame (" + image_check + ") is not right yet, so its work is not credited";
  else if (!within_coverage)
    r.note = "more fragments were shaded than the framework's volumes shade: work outside a light's sphere in depth "
             "(depth(off) shades the surfaces behind a volume and the background; cull(none) shades twice where the "
             "surface lies in front of it), a volume larger than its radius, or a full-screen pass per light";
  else if (!fast_enough)
    r.note = "the volumes save less work than they should on this scene";
  if (!r.passed) r.summary = "Over the limit: " + r.summary;
  return r;
}

std::vector<float> volume_evidence_signature(const VolumeEvidence& e) {
  if (e.lights == 0) return {};
  const double footprint = static_cast<double>(std::max<uint64_t>(e.footprint, 1));
  const double missing = static_cast<double>(e.missing), extra = static_cast<double>(e.extra);
  const double size = std::fabs(missing - extra) / footprint;
  const double place = 2.0 * std::min(missing, extra) / footprint;
  const double state = static_cast<double>(e.shaded_wrong) / static_cast<double>(std::max<uint64_t>(e.must_shade, 1)) +
                       (e.adds ? 0.0 : 1.0);
  std::vector<float> out;
  for (double share : {size, place, state})
    out.insert(out.end(), kEvidenceWidth, static_cast<float>(kSignatureCap * std::min(share, 1.0)));
  return out;
}

std::string describe_volume_evidence(const VolumeEvidence& e) {
  std::string out;
  auto add = [&](const std::string& sentence) { out += (out.empty() ? "" : "; ") + sentence; };
  // A sliver at the volume's edge is rasterisation, not a mistake: 2 % of its footprint.
  const uint64_t off = e.worst_missing + e.worst_extra;
  if (e.worst_volume_light >= 0 && off * 50 > std::max<uint64_t>(e.worst_footprint, 1)) {
    const char* what = e.worst_missing > 0 && e.worst_extra > 0 && std::min(e.worst_missing, e.worst_extra) * 4 > off
                           ? "it lies elsewhere than its light"
                       : e.worst_missing > e.worst_extra ? "too small"
                                                         : "too large";
    char text[320];
    std::snprintf(text, sizeof text,
                  "light %d's volume, drawn alone, leaves out %llu of the %llu pixels its sphere covers on screen and "
                  "covers %llu outside it: %s",
                  e.worst_volume_light + 1, static_cast<unsigned long long>(e.worst_missing),
                  static_cast<unsigned long long>(e.worst_footprint), static_cast<unsigned long long>(e.worst_extra), what);
    add(text);
  }
  if (e.worst_state_light >= 0 && e.worst_shaded != e.worst_must_shade) {
    char text[320];
    std::snprintf(text, sizeof text,
                  "light %d has %llu surface pixels inside its sphere, and the volume's state let %llu fragments reach "
                  "them (one each is right: %s)",
                  e.worst_state_light + 1, static_cast<unsigned long long>(e.worst_must_shade),
                  static_cast<unsigned long long>(e.worst_shaded),
                  e.worst_shaded > e.worst_must_shade ? "some pixels are shaded twice" : "some pixels get no light");
    add(text);
  }
  if (e.lights > 0 && !e.adds) add("blend(off): each light's term replaces what is already in the target instead of adding to it");
  return out;
}

std::set<std::string> volume_evidence_parts(const VolumeEvidence& e) {
  std::set<std::string> parts;
  const uint64_t off = e.worst_missing + e.worst_extra;
  // The thresholds of describe_volume_evidence: a sliver at the edge is rasterisation.
  if (e.worst_volume_light >= 0 && off * 50 > std::max<uint64_t>(e.worst_footprint, 1))
    parts.insert(e.worst_missing > 0 && e.worst_extra > 0 && std::min(e.worst_missing, e.worst_extra) * 4 > off
                     ? "light_volume.vert, placement"
                     : "light_volume.vert, radius");
  const uint64_t state_off =
      e.worst_shaded > e.worst_must_shade ? e.worst_shaded - e.worst_must_shade : e.worst_must_shade - e.worst_shaded;
  if (e.worst_state_light >= 0 && state_off * 50 > std::max<uint64_t>(e.worst_must_shade, 1))
    parts.insert("light_volume.vert, state");
  if (e.lights > 0 && !e.adds) parts.insert("light_volume.vert, blend");
  return parts;
}

Image display_image(Metric metric, const Image& image, const Image& reference) {
  Image out(image.width, image.height, 3);
  float lo[3] = {0, 0, 0}, span[3] = {1, 1, 1};
  if (metric == Metric::Position) {
    float hi[3] = {-1e30f, -1e30f, -1e30f};
    for (int c = 0; c < 3; ++c) lo[c] = 1e30f;
    for (int y = 0; y < reference.height; ++y)
      for (int x = 0; x < reference.width; ++x) {
        if (reference.channels < 4 || reference.at(x, y, 3) < 0.5f) continue;
        for (int c = 0; c < 3; ++c) {
          lo[c] = std::min(lo[c], reference.at(x, y, c));
          hi[c] = std::max(hi[c], reference.at(x, y, c));
        }
      }
    for (int c = 0; c < 3; ++c) {
      if (lo[c] > hi[c]) lo[c] = hi[c] = 0.0f;
      span[c] = std::max(hi[c] - lo[c], 1e-3f);
    }
  }
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      bool finite = true;
      float length2 = 0.0f;
      for (int c = 0; c < image.channels; ++c) finite = finite && std::isfinite(image.at(x, y, c));
      for (int c = 0; c < std::min(3, image.channels); ++c) length2 += image.at(x, y, c) * image.at(x, y, c);
      for (int c = 0; c < 3; ++c) {
        float v = c < image.channels ? image.at(x, y, c) : 0.0f;
        switch (metric) {
          case Metric::Hdr: v = std::pow(std::max(v, 0.0f) / (1.0f + std::max(v, 0.0f)), 1.0f / kDisplayGamma); break;
          case Metric::Position: v = image.channels > 3 && image.at(x, y, 3) >= 0.5f ? (v - lo[c]) / span[c] : 0.0f; break;
          case Metric::Normal:  // no normal written (background): black, not mid-grey
            v = length2 < kMinNormalLength * kMinNormalLength ? 0.0f : 0.5f * (v + 1.0f);
            break;
          case Metric::Material: v = c == 2 ? v / (1.0f + std::fabs(v)) : v; break;
          default: break;
        }
        if (!finite) v = c == 1 ? 0.0f : 1.0f;  // magenta
        out.at(x, y, c) = v;
      }
    }
  }
  return out;
}

}  // namespace kit::grade
