#pragma once
// What kit-grade writes for a submission: results.json (Gradescope's
// autograder format), summary.json (per-lab scores and statuses for scripts),
// report.html (one row per check, images beside it) and, for a batch,
// gradebook.csv. Everything that came from the student is escaped.
#include <nlohmann/json.hpp>

#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "outcome.h"

namespace kit::grade {

nlohmann::json results_json(const SubmissionOutcome& outcome);
nlohmann::json summary_json(const SubmissionOutcome& outcome);
std::string report_html(const SubmissionOutcome& outcome);

// results.json, summary.json and report.html into `dir`, each written to a
// temporary file first and renamed, so a reader never sees half a file.
void write_results(const std::filesystem::path& dir, const SubmissionOutcome& outcome);

// "lab 3 attenuation: 6.667/10  (4 of 6 checks passed)" or "... 0/10  (compile error: first line)".
std::string lab_line(const LabOutcome& lab);
// "lab 2 lighting"
std::string lab_title(int lab);
// A score in thousandths, exactly: "6.667", "6.5", "10" (every score kit-grade prints).
std::string format_points(Thousandths points);
// The same as a JSON number (6.667) and back (summary.json's numbers, rounded to thousandths).
double points_value(Thousandths points);
Thousandths points_from_value(double value);
// Any other number for people (seconds, factors): at most two decimals.
std::string format_score(double score);

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

std::string html_escape(const std::string& text);

}  // namespace kit::grade
