#pragma once
// What kit-grade writes for a submission: results.json (Gradescope's
// autograder format), summary.json (per-lab scores and statuses for scripts),
// report.html (one row per check, images beside it); a batch's own files are
// class_summary.h's. Everything that came from the student is escaped.
#include <nlohmann/json_fwd.hpp>

#include <filesystem>
#include <string>
#include <vector>

#include "verdict/outcome.h"

namespace kit::grade {

nlohmann::json results_json(const SubmissionOutcome& outcome);
nlohmann::json summary_json(const SubmissionOutcome& outcome);
std::string report_html(const SubmissionOutcome& outcome);

// results.json, summary.json and report.html into `dir`, each written to a
// temporary file first and renamed, so a reader never sees half a file.
void write_results(const std::filesystem::path& dir, const SubmissionOutcome& outcome);
// summary.json's "likely_mistakes" of a lab: id, description and similarity (to thousandths).
nlohmann::json likely_mistakes_json(const std::vector<LikelyMistake>& mistakes);

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

std::string html_escape(const std::string& text);

}  // namespace kit::grade
