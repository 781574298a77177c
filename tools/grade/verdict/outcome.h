#pragma once
// What grading a submission comes to: each check's comparison and points, each lab's status
// and checks, the submission's labs and notes. The grader fills them (run/lab_results.cpp) and the
// browser's in-page check fills a lab's (lab_verdict.h); report.h writes them.
#include <filesystem>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "frames/function_probes.h"
#include "verdict/compare.h"
#include "verdict/config.h"
#include "verdict/diagnosis.h"

namespace kit::grade {

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
  // The lab's share of its render worker (render_worker.h): wall time from the lab's start
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
  // Lab 7: what its per-light counts (render/light_volumes.h VolumeEvidence) and work checks
  // say is wrong, as parts that naming weighs beside the probes' (compare.h, evidence_parts).
  std::set<std::string> evidence;
  bool volume_counted = false;  // those counts were taken (not in the browser: WebGL2 counts no samples)
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
  std::string renderer;             // GL_RENDERER of the render workers
  std::string references_renderer;  // what rendered the references they were compared with
  std::string measured_on;          // the implementations the tolerances were measured on (Config)
  bool within_measured = true;      // `renderer` is one of them: else the report says so
  bool gpu = false;                 // graded with --gpu: the report says the verdict is the GPU's
  double seconds = 0.0;
  Thousandths total() const;
  Thousandths max_total() const;
  bool grader_error() const;        // a lab could not be rendered for the grader's own reasons
};

}  // namespace kit::grade
