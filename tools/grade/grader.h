#pragma once
// The grading run: sanitizes submissions, renders each lab in a child process
// (up to --jobs at a time, across labs and submissions), compares the renders
// with the references and writes each submission's results as it completes.
#include <filesystem>
#include <vector>

#include "gl/context.h"
#include "sandbox.h"

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

// Said in the notes when lab 5's custom effect was rendered on the submission's own bloom
// (render_child.cpp, isolated_custom_library): a kit without lab 5's solution.
constexpr const char* kOwnBloomNote =
    "this kit has no reference solution of this lab (a student copy), so the custom effect was graded on your own "
    "bloom; the official grader isolates it on the reference bloom, so a bloom mistake costs points here that it "
    "does not there, and a correct lab gets the same marks in both";

// The order a run renders its labs in (`labs` ascending, `jobs` workers at once):
// the longest first, then the lab whose comparison costs most (grader.cpp says why).
std::vector<int> lab_start_order(const std::vector<int>& labs, int jobs);
// `kit-grade SUBMISSION`: returns the process exit status.
int grade_submission(const std::filesystem::path& submission, const Options& options);
// `kit-grade --prepare-references DIR`: the references of options.labs decoded into DIR
// with their backgrounds and report PNGs, as a run's cache holds them, for runs to read
// (prepared_references_dir(); the build runs it, tools/grade.cmake). References that are
// stale or missing are left out with a message: grading makes them in its cache. Returns 0.
int prepare_references(const Options& options, const std::filesystem::path& out);
// `kit-grade --batch FOLDER` is batch.h's; `--update-references` and
// `--check-references` are reference_maintenance.h's.

}  // namespace kit::grade
