#pragma once
// `kit-grade --batch FOLDER`: every submission of a folder graded in one run into
// its own result folder under --out, plus the gradebook. A result stands while its
// submission holds what it held when graded (its content hash); one batch at a time
// writes an output folder (its lock).
#include <filesystem>

#include "run/options.h"

namespace kit::grade {

int grade_batch(const std::filesystem::path& folder, const Options& options);

}  // namespace kit::grade
