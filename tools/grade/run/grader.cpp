#include "run/grader.h"

#include <nlohmann/json.hpp>

#include <cstdio>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include "base/error.h"
#include "files/files.h"
#include "frames/checks.h"
#include "intake/submission.h"
#include "reference_store/references.h"
#include "report/report.h"
#include "run/grading_run.h"
#include "run/lab_results.h"
#include "run/scheduler.h"
#include "verdict/compare.h"
#include "verdict/diagnosis.h"
#include "verdict/lab_verdict.h"

namespace fs = std::filesystem;

namespace kit::grade {

namespace {

void print_submission(const SubmissionOutcome& s) {
  if (!s.problem.empty()) std::printf("%s: %s\n", s.name.c_str(), s.problem.c_str());
  for (const auto& [number, lab] : s.labs) std::printf("%s\n", lab_line(lab).c_str());
  std::printf("total: %s/%s\n", format_points(s.total()).c_str(), format_points(s.max_total()).c_str());
  std::fflush(stdout);
}

}  // namespace

int grade_submission(const fs::path& submission, const Options& options) {
  std::error_code ec;
  if (!fs::exists(fs::symlink_status(submission, ec))) throw Error(submission.string() + ": no such folder or file");
  std::string why;
  if (!writable_folder(options.out, &why)) throw Error(why);
  Run run = make_run(options, true);
  std::vector<Entry> entries(1);
  entries[0].source = submission;
  entries[0].result_dir = options.out;
  entries[0].content_hash = content_hash(submission);
  bool grader_error = false;
  bool completed = run_entries(run, entries, [&](Entry& e) {
    write_results(options.out, e.outcome);
    if (!options.quiet) print_submission(e.outcome);
    grader_error = e.outcome.grader_error();
  });
  remove_run_temp(run);
  if (!completed) return 130;
  if (grader_error) {
    std::fprintf(stderr, "kit-grade: the grader could not grade every lab (see %s)\n", (options.out / "summary.json").c_str());
    return 2;
  }
  return 0;
}

int prepare_references(const Options& options, const fs::path& out) {
  const fs::path dir = options.references.empty() ? default_references_dir() : options.references;
  try {
    require_current_references(dir);
    fs::create_directories(out);
    for (int lab : options.labs) {
      // Made as a grading run's cache holds them: the same names and bytes (no prepared folder to read).
      const std::map<std::string, LoadedReference> references = load_lab_references(dir, lab, out);
      for (const Check* check : lab_checks(lab)) {
        if (compares_own_renders(check->metric)) continue;
        const LoadedReference& reference = references.at(check->reference);
        cached_background(reference, check->metric);
        cache_png(reference_png(reference, *check),
                  [&] { return display_image(shown_metric(*check), reference.image, reference.image); });
      }
      // And those a failed check's worst pixel is described from (made at their own stage).
      for (const RenderSpec* spec : lab_renders(lab, true))
        if (spec->describes_pixels_only) load_describing_reference(dir, spec->id, out);
    }
  } catch (const std::exception& e) {  // grading makes them in its cache instead
    std::fprintf(stderr, "kit-grade: the references were not prepared in %s: %s\n", out.c_str(), e.what());
  }
  return 0;
}

int name_again(const std::vector<fs::path>& results, const Options& options) {
  const fs::path dir = options.references.empty() ? default_references_dir() : options.references;
  const MistakeSignatures mistakes = load_mistake_signatures(dir / kMistakeSignaturesFile);
  nlohmann::json out = nlohmann::json::object();
  for (const fs::path& result : results) {
    if (!fs::is_regular_file(result / "summary.json"))
      throw Error(result.string() + ": not a result folder of kit-grade's (no summary.json)");
    const fs::path file = result / kNamingInputsFile;
    nlohmann::json labs = nlohmann::json::object();
    std::ifstream in(file);
    if (in) {  // else every graded lab passed: nothing to name
      try {
        const nlohmann::json doc = nlohmann::json::parse(in);
        for (const auto& [lab, inputs] : doc.items())
          labs[lab] = likely_mistakes_json(likely_mistakes(mistakes, std::stoi(lab), naming_inputs_from_json(inputs)));
      } catch (const std::exception& e) {  // JSON's, stoi's and naming_inputs_from_json's
        throw Error(file.string() + ": " + e.what());
      }
    }
    out[result.string()] = labs;
  }
  std::printf("%s\n", out.dump(1).c_str());
  return 0;
}

}  // namespace kit::grade
