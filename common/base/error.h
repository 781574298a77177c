#pragma once
// One exception type for everything the kit reports to a person: the message
// is complete on its own (file, line, what is wrong), so callers print what().
#include <cstdio>
#include <exception>
#include <functional>
#include <stdexcept>
#include <string>

namespace kit {

struct Error : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// A tool's main body: its status, or `failure_status` after printing
// "TOOL: message" for a kit::Error ("TOOL: unexpected error: ..." for any other
// exception), so every tool fails the same way and never with a bare abort.
inline int run_tool(const char* tool, int failure_status, const std::function<int()>& body) {
  try {
    return body();
  } catch (const Error& e) {
    std::fprintf(stderr, "%s: %s\n", tool, e.what());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s: unexpected error: %s\n", tool, e.what());
  }
  return failure_status;
}

}  // namespace kit
