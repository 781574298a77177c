#pragma once
// The grading run's scheduler: every lab of every entry rendered in render workers
// (render_worker.h), up to --jobs at a time across labs and submissions, each lab compared
// as its worker reports it (lab_results.h), and each entry handed on as it completes.
#include <functional>
#include <vector>

#include "intake/sandbox.h"
#include "run/grading_run.h"

namespace kit::grade {

// Called as each entry has all its labs graded.
using Finished = std::function<void(Entry&)>;

// Runs every lab of every entry in render workers (render_worker.h), at most options.jobs
// at a time, each rendering labs of one submission one after another; `finished` is
// called as each entry completes. Returns false when interrupted.
bool run_entries(Run& run, std::vector<Entry>& entries, const Finished& finished);
// The order a run renders its labs in (`labs` ascending, `jobs` workers at once):
// the longest first, then the lab whose comparison costs most (scheduler.cpp says why).
std::vector<int> lab_start_order(const std::vector<int>& labs, int jobs);
// Whether a lab whose worker ended while rendering it, after `labs_before` other labs,
// is rendered again as the first lab of a fresh worker, so that its verdict is the one a
// process of its own gives.
bool render_again_alone(const Outcome& ended, int labs_before);

}  // namespace kit::grade
