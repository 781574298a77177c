#pragma once
// What a kit-grade command runs with, from its command line (main.cpp).
#include <filesystem>
#include <vector>

#include "gl/context.h"
#include "intake/sandbox.h"

namespace kit::grade {

struct Options {
  std::vector<int> labs;               // --labs (default: every lab)
  std::filesystem::path out;           // --out
  int jobs = 1;                        // --jobs: labs rendered at the same time
  Backend backend = default_headless_backend();   // --backend
  // Mesa's software rasteriser, the implementations the tolerances were measured on,
  // whatever GPU the machine has; --gpu: whatever device the platform gives first.
  Device device = Device::Software;
  Limits limits;                       // --timeout, --cpu-limit, --memory-limit
  std::filesystem::path config;        // --config (default tools/grade/grading.json)
  std::filesystem::path references;    // --references (default tools/grade/references)
  bool force = false;                  // --force: regrade batch submissions that have unchanged results
  bool keep_temp = false;              // --keep-temp: leave the private copies and raw renders
  bool quiet = false;                  // no per-lab lines (batch prints one line per submission)
};

}  // namespace kit::grade
