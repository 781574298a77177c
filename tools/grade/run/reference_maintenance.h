#pragma once
// Keeping the reference renders current: `kit-grade --update-references` renders
// solutions/ into them (references.h writes the files and their manifest);
// `--check-references` re-renders the solutions and fails when the references are stale.
#include "run/options.h"

namespace kit::grade {

// `kit-grade --update-references` / `--check-references`: return the process exit status.
int update_references(const Options& options);
int check_references(const Options& options);

}  // namespace kit::grade
