#pragma once
// What a batch writes beside its result folders, from the summary.json of each submission:
// gradebook.csv, and what the class gets wrong (class-summary.csv and class-summary.html).
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json_fwd.hpp>

namespace kit::grade {

// A batch's submissions, in the gradebook's order: each name with its summary.json, read once
// for the gradebook and the class summary (null where it cannot be read).
using BatchSummaries = std::vector<std::pair<std::string, nlohmann::json>>;
// The summary.json of each submission's result folder under `dir`: (submission name, result
// folder name) pairs.
BatchSummaries read_batch_summaries(const std::filesystem::path& dir,
                                    const std::vector<std::pair<std::string, std::string>>& submissions);

// gradebook.csv in `dir` (a summary that could not be read says so in its row).
void write_gradebook(const std::filesystem::path& dir, const BatchSummaries& summaries, const std::vector<int>& labs);

// What a class gets wrong, from the same summaries: class-summary.csv and
// class-summary.html in `dir`. Per lab: the score distribution (tenths of the lab's
// points), each check's pass count, and each likely mistake named first with how many
// submissions it was named for. CSV rows: lab,what,key,title,count,submissions, `what`
// being "score" (key: the bin, "0-1" ... "9-10" in tenths of the maximum, "10" full marks),
// "check" (count: submissions that passed it) or "mistake" (count: submissions it was named
// first for). The HTML page charts the distribution (inline SVG: nothing loaded from elsewhere).
void write_class_summary(const std::filesystem::path& dir, const BatchSummaries& summaries,
                         const std::vector<int>& labs);

}  // namespace kit::grade
