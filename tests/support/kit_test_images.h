#pragma once
// Image comparisons shared by the tests that check images for identity or difference.
#include <string>

#include "images/image_io.h"

namespace kit::test {

// Mean absolute per-channel difference over all pixels; +inf when the sizes differ.
double mean_abs_difference(const Image& a, const Image& b);

// Empty when `a` and `b` are bitwise identical (same size, same float bits in every
// channel); otherwise a description of the first difference, for the failure message.
std::string first_difference(const Image& a, const Image& b);

}  // namespace kit::test
