#include "run/reference_maintenance.h"

#include <nlohmann/json.hpp>

#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include "base/error.h"
#include "frames/checks.h"
#include "frames/function_probes.h"
#include "frames/light_shares.h"
#include "images/image_io.h"
#include "reference_store/references.h"
#include "render/stages.h"
#include "report/report.h"
#include "run/grading_run.h"
#include "run/scheduler.h"
#include "verdict/compare.h"

namespace fs = std::filesystem;

namespace kit::grade {

namespace {

// "1,2,3", or "none".
std::string labs_list(const std::vector<int>& labs) {
  std::string out;
  for (int lab : labs) out += (out.empty() ? "" : ",") + std::to_string(lab);
  return out.empty() ? "none" : out;
}

// "lab 2 lighting: crash: ...": a lab of the solutions that did not render.
std::string not_graded(int n, const LabOutcome& lab) { return lab_title(n) + ": " + lab.status + ": " + lab.message; }

// Renders the solutions of the run's labs into `collected` (render id -> image), with the
// run's workers as they are set now; `finished` sees their outcome. False when stopped.
bool render_solutions(Run& run, std::map<std::string, Image>& collected, const Finished& finished) {
  run.collect = &collected;
  std::vector<Entry> entries(1);
  entries[0].source = kit_root() / "solutions";
  entries[0].result_dir = run.temp / "unused";
  return run_entries(run, entries, finished);
}

// The metric a G-buffer attachment is compared under (emitted radiance like HDR radiance).
Metric attachment_metric(View view) {
  switch (view) {
    case View::Position: return Metric::Position;
    case View::Normal: return Metric::Normal;
    case View::Albedo: return Metric::Albedo;
    case View::Material: return Metric::Material;
    default: return Metric::Hdr;
  }
}

// The references kept only to describe a worst pixel (checks.h, describes_pixels_only),
// which no check compares: the solutions of the labs that make them (of `o.labs`) render
// them again, and each must match its file as a check's reference must (no pixel over its
// attachment's threshold). What differs is added to `stale`; false when the run was stopped.
bool check_describing_references(const Options& o, const Config& config, const fs::path& dir,
                                 std::vector<std::string>& stale) {
  Options making = o;
  making.labs.clear();
  for (int lab : o.labs)
    if (lab_renders(lab, true).size() != lab_renders(lab).size()) making.labs.push_back(lab);
  if (making.labs.empty()) return true;
  Run run = make_run(making, false);
  std::map<std::string, Image> collected;
  const bool completed = render_solutions(run, collected, [&](Entry& e) {
    for (const auto& [n, lab] : e.outcome.labs)
      if (lab.status != kGraded) stale.push_back(not_graded(n, lab));
  });
  remove_run_temp(run);
  for (int lab : making.labs)
    for (const RenderSpec* spec : lab_renders(lab, true)) {
      auto it = collected.find(spec->id);
      if (!spec->describes_pixels_only || it == collected.end()) continue;
      if (spec->light_shares) {
        const std::string differs =
            compare_light_shares(it->second, read_image((dir / (spec->id + "." + reference_extension(*spec))).string()));
        if (!differs.empty()) stale.push_back(spec->id + " (kept to describe a worst pixel): " + differs);
        continue;
      }
      const Metric metric = attachment_metric(spec->view);
      Tolerance tolerance = config.tolerances.at(metric_name(metric));
      tolerance.fail_percent = 0.0;
      const Image reference = read_image((dir / (spec->id + "." + reference_extension(*spec))).string());
      const Comparison c = compare_images(metric, tolerance, it->second, reference, nullptr, nullptr);
      if (!c.passed) stale.push_back(spec->id + " (kept to describe a worst pixel): " + c.summary);
    }
  return completed;
}

}  // namespace

int update_references(const Options& options) {
  Options o = options;
  o.labs.clear();
  for (const Stage& s : stages()) o.labs.push_back(s.number);
  Run run = make_run(o, false);
  write_cache_seed(run);
  std::string failures, renderer;
  const Finished note_failures = [&](Entry& e) {
    renderer = e.outcome.renderer;
    for (const auto& [n, lab] : e.outcome.labs)
      if (lab.status != kGraded) failures += "\n  " + not_graded(n, lab);
  };
  std::map<std::string, Image> collected;
  std::map<std::string, ProbeValues> probes;
  run.collect_probes = &probes;
  bool completed = render_solutions(run, collected, note_failures);
  run.collect_probes = nullptr;  // the filter renderings' probe values are not the references'

  const std::string reference_renderer = renderer;
  // The filter renderings (references.h), where llvmpipe made the references: only it
  // reads GALLIVM_PERF. Their workers write no shader cache (the seed's programs were
  // compiled without it) and read none.
  std::vector<std::map<std::string, Image>> variants;
  const bool llvmpipe = renderer.find("llvmpipe") != std::string::npos;
  if (llvmpipe) run.writes_cache_seed = false;
  run.collect_describing = false;
  for (size_t i = 0; completed && failures.empty() && llvmpipe && i < kFilterRenderings.size(); ++i) {
    run.child_environment = {{"GALLIVM_PERF", kFilterRenderings[i].name}, {"MESA_SHADER_CACHE_DISABLE", "true"}};
    completed = render_solutions(run, variants.emplace_back(), note_failures);
  }
  remove_run_temp(run);
  if (!completed) return 130;
  if (!failures.empty()) throw Error("the solutions did not render:" + failures);
  fs::path dir = o.references.empty() ? default_references_dir() : o.references;
  const std::map<std::string, Image> allowances = filter_allowances(collected, variants);
  std::vector<std::string> changed = write_references(dir, collected, allowances, reference_renderer);
  // The probed functions' values of the solutions (function_probes.h). A function the
  // solutions no longer declare (a course that changed the lab's equations) has its probe
  // left out, and said so: its lines in function_probes.cpp and the probe shader go next.
  std::vector<std::pair<const FunctionProbe*, ProbeValues>> expected;
  std::vector<std::string> left_out;
  for (const FunctionProbe& probe : all_function_probes()) {
    auto it = probes.find(probe.id);
    if (it != probes.end() && it->second.error.empty() && it->second.values.size() == probe.cases.size())
      expected.emplace_back(&probe, it->second);
    else
      left_out.push_back(probe.title() + " (lab " + std::to_string(probe.lab) + ", " + probe.file + "): " +
                         (it == probes.end() ? std::string("not probed") : it->second.error));
  }
  for (const std::string& file : write_probes_reference(dir, probes_reference_json(expected))) changed.push_back(file);
  std::printf("kit-grade: %zu references in %s (%s), %zu with a filter allowance%s: %zu file(s) changed, the others "
              "kept byte for byte; check them with --check-references\n",
              reference_renders().size(), dir.c_str(), reference_renderer.c_str(), allowances.size(),
              llvmpipe ? "" : " (only llvmpipe renders the filter renderings)", changed.size());
  for (const std::string& file : changed) std::printf("  changed: %s\n", file.c_str());
  for (const std::string& probe : left_out)
    std::printf("  function probe left out, the solutions do not declare it as tools/grade/frames/function_probes.cpp "
                "says: %s\n", probe.c_str());
  return 0;
}

int check_references(const Options& options) {
  Options o = options;
  // The labs whose solutions this kit holds: every lab in the instructor's kit, the
  // released ones in a student copy (whose references are checked all the same).
  o.labs = labs_with_solutions();
  fs::path dir = o.references.empty() ? default_references_dir() : o.references;
  std::vector<std::string> stale = manifest_differences(dir);
  if (stale.empty() && !o.labs.empty()) {
    Run run = make_run(o, true);
    write_cache_seed(run);
    // Stale means: any pixel of a solution over its per-pixel threshold (no share of failing pixels allowed).
    for (auto& [metric, tolerance] : run.config.tolerances) tolerance.fail_percent = 0.0;
    for (auto& [check, tolerance] : run.config.check_tolerances) tolerance.fail_percent = 0.0;
    std::vector<Entry> entries(1);
    entries[0].source = kit_root() / "solutions";
    entries[0].result_dir = run.temp / "result";
    bool completed = run_entries(run, entries, [&](Entry& e) {
      for (const auto& [n, lab] : e.outcome.labs) {
        if (lab.status != kGraded) stale.push_back(not_graded(n, lab));
        for (const CheckOutcome& c : lab.checks)
          if (lab.status == kGraded && !c.passed)
            stale.push_back(lab_title(n) + ": " + c.check->title + ": " + c.comparison.note +
                            (c.comparison.note.empty() ? "" : "; ") + c.comparison.summary);
        // The solution's functions must agree with probes.json where it holds them (a student
        // copy keeps the probes of the labs it releases; a probe the solutions cannot run is
        // left out of it by --update-references).
        for (const ProbeOutcome& p : lab.probes)
          if (lab.status == kGraded && p.status != kProbeAgrees &&
              !expected_probe_values(run.probes_reference, *p.probe).empty())
            stale.push_back(lab_title(n) + ": probes.json: " + p.message);
      }
    });
    remove_run_temp(run);
    if (completed) completed = check_describing_references(o, run.config, dir, stale);
    if (!completed) return 130;
  }
  if (stale.empty()) {
    std::printf("kit-grade: the references in %s match the check list (%zu images) and the solutions of labs %s\n",
                dir.c_str(), reference_renders().size(), labs_list(o.labs).c_str());
    return 0;
  }
  std::printf("kit-grade: the references in %s are stale (run kit-grade --update-references):\n", dir.c_str());
  for (const std::string& s : stale) std::printf("  %s\n", s.c_str());
  return 1;
}

}  // namespace kit::grade
