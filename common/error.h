#pragma once
// One exception type for everything the kit reports to a person: the message
// is complete on its own (file, line, what is wrong), so callers print what().
#include <stdexcept>
#include <string>

namespace kit {

struct Error : std::runtime_error {
  using std::runtime_error::runtime_error;
};

}  // namespace kit
