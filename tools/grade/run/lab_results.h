#pragma once
// What a run makes of a lab once its render worker has ended it: its status from how the
// worker ended, its checks compared with the references (lab_verdict.h), each check's report
// images, and what the submission's notes say of it.
#include <filesystem>
#include <functional>

#include "frames/checks.h"
#include "images/image_io.h"
#include "intake/sandbox.h"
#include "reference_store/references.h"
#include "run/grading_run.h"
#include "verdict/outcome.h"

namespace kit::grade {

// Lab `lab` with its checks and their points (the run's config), nothing compared yet.
LabOutcome empty_lab(const Run& run, int lab);
// Lab `lab` of entry `e`, which its render worker ended as `ended`: graded from what the
// worker left in its folder (render_worker.h, lab_folder), its report images written into
// e.result_dir; e's outcome gets the renderer and a note where the lab says one.
LabOutcome grade_rendered_lab(Run& run, Entry& e, int lab, const Outcome& ended);

// Writes `cached`, a PNG in the reference cache, from make() unless it is there. False
// when the cache cannot hold it: the caller writes its own file.
bool cache_png(const std::filesystem::path& cached, const std::function<Image()>& make);
// The cached report PNG of `check`'s reference; "" where the reference is prepared by the
// build (only read) without it.
std::filesystem::path reference_png(const LoadedReference& reference, const Check& check);

}  // namespace kit::grade
