#include "frames/light_shares.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "base/error.h"

namespace kit::grade {

namespace {

// Rec. 709, as shaders/math.glsl's KIT_LUMINANCE.
double luminance(const Image& image, int x, int y) {
  return 0.2126 * image.at(x, y, 0) + 0.7152 * image.at(x, y, 1) + 0.0722 * image.at(x, y, 2);
}

// A share to 1/256: the file compresses, and a description prints whole percents.
constexpr double kShareSteps = 256.0;
// Below this summed luminance a pixel has no light to share (a half float's smallest normal).
constexpr double kNoLight = 6.103515625e-05;
// compare_light_shares: an HDR check's per-pixel threshold (grading.json), after c / (1 + c).
constexpr double kLuminanceThreshold = 0.01;

// The summed luminance to 7 significant bits (steps under 1 %): the file compresses (a float's
// 24 bits took 5 times the bytes of the shares), and a description prints 2 digits.
double to_significant_bits(double value) {
  int exponent = 0;
  const double mantissa = std::frexp(value, &exponent);  // in [0.5, 1)
  return std::ldexp(std::round(mantissa * 128.0) / 128.0, exponent);
}

}  // namespace

Image light_shares_image(const std::vector<Image>& alone, const Image& none) {
  Image out(none.width, none.height, 4);
  for (const Image& image : alone)
    if (image.width != none.width || image.height != none.height || image.channels < 3)
      throw Error("light shares: a light's frame is not the size of the frame without lights");
  std::vector<LightShare> lights(alone.size());
  for (int y = 0; y < none.height; ++y)
    for (int x = 0; x < none.width; ++x) {
      const double base = luminance(none, x, y);
      double sum = 0.0;
      for (size_t i = 0; i < alone.size(); ++i) {
        // Each light's own frame differs from the one without lights by its light alone; a
        // rounding below zero is none. Its luminance, until divided by the sum below.
        const double own = luminance(alone[i], x, y) - base;
        lights[i] = {static_cast<int>(i), std::isfinite(own) ? std::max(own, 0.0) : 0.0};
        sum += lights[i].share;
      }
      out.at(x, y, 3) = static_cast<float>(to_significant_bits(sum));
      if (!(sum > kNoLight)) continue;
      const size_t named = std::min(lights.size(), static_cast<size_t>(kSharedLights));
      std::partial_sort(lights.begin(), lights.begin() + static_cast<std::ptrdiff_t>(named), lights.end(),
                        [](const LightShare& a, const LightShare& b) {
                          return a.share > b.share || (a.share == b.share && a.light < b.light);
                        });
      for (size_t k = 0; k < named; ++k) {
        const double share = std::round(lights[k].share / sum * kShareSteps) / kShareSteps;
        if (share > 0.0) out.at(x, y, static_cast<int>(k)) = static_cast<float>(lights[k].light + 1 + share / 2.0);
      }
    }
  return out;
}

PixelLightShares light_shares_at(const Image& shares, int x, int y) {
  PixelLightShares out;
  if (shares.channels < 4 || x < 0 || y < 0 || x >= shares.width || y >= shares.height) return out;
  out.luminance = shares.at(x, y, 3);
  for (int k = 0; k < kSharedLights; ++k) {
    const double v = shares.at(x, y, k);
    if (!(v >= 1.0)) continue;
    const double number = std::floor(v);
    out.lights.push_back({static_cast<int>(number) - 1, std::min(2.0 * (v - number), 1.0)});
  }
  return out;
}

std::string compare_light_shares(const Image& made, const Image& stored) {
  if (made.width != stored.width || made.height != stored.height || made.channels != 4 || stored.channels != 4)
    return "not the size of the frame";
  size_t luminance_off = 0, light_off = 0;
  for (int y = 0; y < made.height; ++y)
    for (int x = 0; x < made.width; ++x) {
      const PixelLightShares a = light_shares_at(made, x, y), b = light_shares_at(stored, x, y);
      // As an HDR check compares (compare.h): after c / (1 + c).
      const auto mapped = [](double c) { return c / (1.0 + c); };
      if (!(std::abs(mapped(std::max(a.luminance, 0.0)) - mapped(std::max(b.luminance, 0.0))) <= kLuminanceThreshold)) {
        ++luminance_off;
        continue;
      }
      const bool both_most = !a.lights.empty() && !b.lights.empty() && a.lights[0].share >= 0.6 && b.lights[0].share >= 0.6;
      if (both_most && a.lights[0].light != b.lights[0].light) ++light_off;
    }
  const size_t pixels = static_cast<size_t>(made.width) * static_cast<size_t>(made.height);
  if (static_cast<double>(luminance_off + light_off) <= 0.005 * static_cast<double>(pixels)) return "";
  char text[160];
  std::snprintf(text, sizeof text, "%zu of %zu pixels with another luminance, %zu with another light most",
                luminance_off, pixels, light_off);
  return text;
}

}  // namespace kit::grade
