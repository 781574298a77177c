#pragma once
// The grading run: sanitizes submissions, renders each lab in a child process
// (up to --jobs at a time, across labs and submissions), compares the renders
// with the references and writes each submission's results as it completes.
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "compare.h"
#include "config.h"
#include "diagnosis.h"
#include "function_probes.h"
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

// Statuses a lab ends with (summary.json "status").
constexpr const char* kGraded = "graded";
constexpr const char* kCompileError = "compile_error";
constexpr const char* kTimeout = "timeout";
constexpr const char* kCrash = "crash";
constexpr const char* kNonFiniteMap = "non_finite_map";  // a lab 6 shader wrote NaN or Inf into a precomputed map
constexpr const char* kMissingFiles = "missing_files";
constexpr const char* kInvalidFiles = "invalid_files";
constexpr const char* kGraderError = "error";  // the grader could not render (no context) or read a reference: exit status 2

struct CheckOutcome {
  const Check* check = nullptr;
  bool passed = false;
  Thousandths score = 0, max_score = 0;  // thousandths of a point (Config::max_score)
  bool compared = false;      // false when the lab was not rendered
  Comparison comparison;
  std::string image, reference, diff;  // report images, relative to the result folder ("" when none)
};

struct LabOutcome {
  int lab = 0;
  std::string status;
  std::string message;        // the problem in plain text (compiler log, missing files, ...)
  std::string folder;         // where its files were taken from, relative to the submission ("" when not found)
  std::vector<CheckOutcome> checks;
  double render_ms = 0.0;     // GPU work of the lab's frames (child.json)
  // The lab's share of its render worker (render_child.h): wall time from the lab's start
  // to its report, and the worker's CPU time (all threads) over that time.
  double child_seconds = 0.0, child_cpu_seconds = 0.0, compare_seconds = 0.0;
  long child_max_rss_kib = 0;   // the worker's peak resident set up to the lab's end
  long child_vm_peak_kib = 0;   // its peak address space up to then (RLIMIT_AS applies to it)
  std::map<std::string, double> child_timings;  // context, compile, render, readback
  // Where a check failed: the catalogued mistakes its signatures resemble, closest first
  // (diagnosis.h); empty when none fits or no signatures were loaded.
  std::vector<LikelyMistake> likely_mistakes;
  bool diagnosed = false;  // a check failed and signatures were there to compare with
  // The lab's probed functions (function_probes.h), in the table's order: they inform, they
  // do not score. Empty for a lab without probes or one that was not rendered.
  std::vector<ProbeOutcome> probes;
  int passed_checks() const;
  // The sums of the checks' integer thousandths: exact, and the very numbers printed.
  Thousandths score() const;
  Thousandths max_score() const;
};

struct SubmissionOutcome {
  std::string name;
  std::filesystem::path source;
  std::string problem;              // whole-submission problem (zip refused, ...)
  std::vector<std::string> notes;
  std::string content_hash;         // content_hash() of the submission when it was graded
  std::map<int, LabOutcome> labs;
  std::string renderer;             // GL_RENDERER of the children
  std::string references_renderer;  // what rendered the references they were compared with
  std::string measured_on;          // the implementations the tolerances were measured on (Config)
  bool within_measured = true;      // `renderer` is one of them: else the report says so
  bool gpu = false;                 // graded with --gpu: the report says the verdict is the GPU's
  double seconds = 0.0;
  Thousandths total() const;
  Thousandths max_total() const;
  bool grader_error() const;        // a lab could not be rendered for the grader's own reasons
};

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
