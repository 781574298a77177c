#include "base/text.h"

#include <algorithm>
#include <cctype>

namespace kit {

std::string lower_case(std::string text) {
  std::transform(text.begin(), text.end(), text.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return text;
}

}  // namespace kit
