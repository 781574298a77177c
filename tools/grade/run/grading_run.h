#pragma once
// The grading run as kit-grade's commands share it: its settings, what its submissions
// share, its temporary folder and shader caches, and its entries. Private to tools/grade:
// grade_submission (grader.cpp), grade_batch (batch.cpp) and the reference commands
// (reference_maintenance.cpp) each make a run, and its scheduler (scheduler.h) renders and
// compares each entry's labs.
#include <chrono>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "frames/function_probes.h"
#include "images/image_io.h"
#include "intake/sandbox.h"
#include "intake/submission.h"
#include "reference_store/references.h"
#include "run/options.h"
#include "scene/scene.h"
#include "verdict/compare.h"
#include "verdict/outcome.h"

namespace kit::grade {

using Clock = std::chrono::steady_clock;

// One grading run: the settings, what every submission shares (config,
// scenes, references) and the run's private temporary folder.
struct Run {
  const Options& options;
  Config config;
  std::map<std::string, Scene> scenes;
  std::filesystem::path references_dir;  // "" when the run compares with none (--update-references)
  // The references of the labs compared so far (load_references_of), each with its
  // background as its checks compare it (reference_background), found once; per lab
  // loaded, "" or why its references could not be read.
  std::map<int, std::string> reference_problems;
  std::map<std::string, LoadedReference> references;
  std::map<std::pair<std::string, Metric>, Background> backgrounds;
  std::map<std::string, Image>* collect = nullptr;  // --update-references: keep the raw renders instead
  std::filesystem::path temp;
  // --check-references and --update-references render only the kit's own files:
  // their workers write the shader cache seed that graded submissions start from.
  bool writes_cache_seed = false;
  // Where the decoded references and what is made from them are kept
  // (reference_cache_dir(): between runs, else in this run's temporary folder).
  std::filesystem::path reference_cache;
  std::filesystem::path prepared_references;  // prepared_references_dir(): the build's, only read
  std::string references_renderer;  // what rendered the references (their manifest's "renderer")
  // <references>/mistakes.json (none when it is not there), read before the first
  // comparison (load_mistakes_once) rather than while the first workers wait to start.
  MistakeSignatures mistakes;
  bool mistakes_loaded = false;
  // The reference G-buffer attachments and light shares a failed check's worst pixel is
  // described from (lab_verdict.h, add_reference_pixel_inputs), read when a check first needs them.
  mutable std::map<std::string, Image> pixel_input_references;
  // Variables set in every render worker after the run's own (--update-references: the
  // filter renderings' GALLIVM_PERF).
  std::vector<std::pair<std::string, std::string>> child_environment;
  // <references>/probes.json (function_probes.h): the reference solutions' values of the
  // probed functions; null when the run compares with none or the file is not there.
  nlohmann::json probes_reference;
  // --update-references: keep the solutions' probe values too, by probe id.
  std::map<std::string, ProbeValues>* collect_probes = nullptr;
  // With collect: the renders that only describe a worst pixel too (checks.h). The filter
  // renderings make allowances for the checks' references alone, and go without them.
  bool collect_describing = true;
  // Whether the workers render, and the run reads back, the describing renders too.
  bool renders_describing() const { return collect != nullptr && collect_describing; }
};

// A submission of a run.
struct Entry {
  std::filesystem::path source;
  std::filesystem::path result_dir;  // report images are written here (a staging folder in a batch)
  std::filesystem::path final_dir;   // a batch: the submission's result folder
  std::string content_hash;  // computed before grading, stored in summary.json
  SubmissionOutcome outcome;
  std::optional<PreparedSubmission> prepared;
  std::filesystem::path temp;
  size_t labs_left = 0;
  Clock::time_point started;
};

// The run of `options`: its config and scenes, its temporary folder, and (with
// `need_references`) its references, which must be current (else kit::Error). Without, a
// run that makes references: the scenes of the renders that only describe a pixel
// (checks.h) are loaded too.
Run make_run(const Options& options, bool need_references);
// Has the run's workers write the Mesa shader cache seed that graded submissions
// start from (runs that render only the kit's own files).
void write_cache_seed(Run& run);
// Makes the entry's temporary folder and its private shader cache, and prepares its
// submission (submission.h): when the scheduler first comes to one of its labs.
void prepare_entry(const Run& run, Entry& e);
// How a render worker of entry `e` starts: in `dir`, with the submission's own shader cache.
ChildSetup render_setup(const Run& run, const Entry& e, const std::filesystem::path& dir);
// Removes the run's temporary folder (--keep-temp: says where it is instead).
void remove_run_temp(const Run& run);

}  // namespace kit::grade
