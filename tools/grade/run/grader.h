#pragma once
// `kit-grade SUBMISSION`: one submission graded in a run of its own (grading_run.h), its
// results written as it completes (report.h); and `kit-grade --prepare-references DIR`.
// `kit-grade --batch FOLDER` is batch.h's; `--update-references` and `--check-references`
// are reference_maintenance.h's.
#include <filesystem>
#include <vector>

#include "run/options.h"

namespace kit::grade {

// `kit-grade SUBMISSION`: returns the process exit status.
int grade_submission(const std::filesystem::path& submission, const Options& options);
// `kit-grade --prepare-references DIR`: the references of options.labs decoded into DIR
// with their backgrounds and report PNGs, as a run's cache holds them, for runs to read
// (prepared_references_dir(); the build runs it, tools/grade.cmake). References that are
// stale or missing are left out with a message: grading makes them in its cache. Returns 0.
int prepare_references(const Options& options, const std::filesystem::path& out);
// `kit-grade --name-again RESULT...`: each result folder's failed labs named again from the
// naming inputs it holds (diagnosis.h, kNamingInputsFile) and the references' mistakes.json as
// it is now, without rendering. Prints {RESULT: {LAB: likely mistakes as summary.json lists
// them}} as JSON (a folder whose labs all passed: {}). Throws kit::Error naming a folder without
// summary.json or a file it cannot read.
int name_again(const std::vector<std::filesystem::path>& results, const Options& options);

}  // namespace kit::grade
