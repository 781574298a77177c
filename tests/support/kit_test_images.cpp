#include "kit_test_images.h"

#include <cmath>
#include <cstring>
#include <limits>

namespace kit::test {

namespace {

bool same_shape(const Image& a, const Image& b) {
  return a.width == b.width && a.height == b.height && a.channels == b.channels &&
         a.pixels.size() == b.pixels.size();
}

std::string shape(const Image& image) {
  return std::to_string(image.width) + "x" + std::to_string(image.height) + "x" + std::to_string(image.channels);
}

}  // namespace

double mean_abs_difference(const Image& a, const Image& b) {
  if (!same_shape(a, b) || a.pixels.empty()) return std::numeric_limits<double>::infinity();
  double sum = 0.0;
  for (size_t i = 0; i < a.pixels.size(); ++i)
    sum += std::fabs(static_cast<double>(a.pixels[i]) - static_cast<double>(b.pixels[i]));
  return sum / static_cast<double>(a.pixels.size());
}

std::string first_difference(const Image& a, const Image& b) {
  if (!same_shape(a, b)) return "sizes differ: " + shape(a) + " vs " + shape(b);
  for (size_t i = 0; i < a.pixels.size(); ++i) {
    // Bits, not values: NaN must equal NaN and 0.0 must differ from -0.0.
    if (std::memcmp(&a.pixels[i], &b.pixels[i], sizeof(float)) != 0) {
      size_t pixel = i / static_cast<size_t>(a.channels);
      return "first difference at pixel (" + std::to_string(pixel % static_cast<size_t>(a.width)) + ", " +
             std::to_string(pixel / static_cast<size_t>(a.width)) + ") channel " +
             std::to_string(i % static_cast<size_t>(a.channels)) + ": " + std::to_string(a.pixels[i]) + " vs " +
             std::to_string(b.pixels[i]);
    }
  }
  return "";
}

}  // namespace kit::test
