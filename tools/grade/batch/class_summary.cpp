#include "batch/class_summary.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <fstream>
#include <map>
#include <set>

#include "files/files.h"
#include "report/report.h"
#include "verdict/outcome.h"

namespace fs = std::filesystem;

namespace kit::grade {

namespace {

// A CSV field: quoted where it holds a comma, a quote or a line break. A leading = + - @
// would make a spreadsheet read a submission's name as a formula: it gets a quote first.
std::string csv_field(std::string field) {
  if (!field.empty() && std::string("=+-@").find(field[0]) != std::string::npos) field = "'" + field;
  if (field.find_first_of(",\"\n\r") == std::string::npos) return field;
  std::string out = "\"";
  for (char c : field) out += c == '"' ? std::string("\"\"") : std::string(1, c);
  return out + "\"";
}

}  // namespace

namespace {

// Lab `lab`'s entry of a summary.json ("labs"."N"), or null where it has none.
const nlohmann::json& lab_entry(const nlohmann::json& summary, int lab) {
  static const nlohmann::json none;
  const auto labs = summary.find("labs");
  if (labs == summary.end() || !labs->is_object()) return none;
  const auto entry = labs->find(std::to_string(lab));
  return entry == labs->end() ? none : *entry;
}

}  // namespace

BatchSummaries read_batch_summaries(const fs::path& dir,
                                    const std::vector<std::pair<std::string, std::string>>& submissions) {
  BatchSummaries out;
  for (const auto& [name, folder] : submissions) {
    std::ifstream in(dir / folder / "summary.json");
    nlohmann::json summary;
    try {
      summary = nlohmann::json::parse(in);
    } catch (const nlohmann::json::exception&) {
      summary = nullptr;
    }
    out.emplace_back(name, std::move(summary));
  }
  return out;
}

void write_gradebook(const fs::path& dir, const BatchSummaries& summaries, const std::vector<int>& labs) {
  std::string text = "submission";
  for (int lab : labs) text += ",lab" + std::to_string(lab);
  text += ",total,max_total,problems\n";
  for (const auto& [name, summary] : summaries) {
    if (!summary.is_object()) {
      text += csv_field(name) + std::string(labs.size() + 2, ',') + "no readable summary.json\n";
      continue;
    }
    std::string row = csv_field(name), problems;
    for (int lab : labs) {
      const nlohmann::json& entry = lab_entry(summary, lab);
      row += "," + (entry.is_object() ? format_points(points_from_value(entry.value("score", 0.0))) : std::string());
      std::string status = entry.is_object() ? entry.value("status", "") : "";
      if (!status.empty() && status != kGraded) problems += (problems.empty() ? "" : " ") + ("lab" + std::to_string(lab) + ":" + status);
    }
    row += "," + format_points(points_from_value(summary.value("total", 0.0))) + "," +
           format_points(points_from_value(summary.value("max_total", 0.0))) + "," + csv_field(problems);
    text += row + "\n";
  }
  write_file_atomic(dir / "gradebook.csv", text);
}

namespace {

// One lab of a class: what write_class_summary counts.
struct LabTally {
  std::vector<int> bins = std::vector<int>(11, 0);  // tenths of the lab's maximum; [10]: full marks
  std::map<std::string, std::pair<std::string, int>> checks;    // key -> (title, passed)
  std::vector<std::string> check_order;
  std::map<std::string, std::pair<std::string, int>> mistakes;  // id -> (description, named first)
  // function -> (file, the submissions where it differs): light_radiance's two settings count once.
  std::map<std::string, std::pair<std::string, std::set<std::string>>> functions;
  int submissions = 0;
};

std::string bin_name(size_t bin) {
  return bin == 10 ? "10" : std::to_string(bin) + "-" + std::to_string(bin + 1);
}

}  // namespace

void write_class_summary(const fs::path& dir, const BatchSummaries& summaries, const std::vector<int>& labs) {
  std::map<int, LabTally> tally;
  for (int lab : labs) tally[lab];
  for (const auto& [name, summary] : summaries) {
    if (!summary.is_object()) continue;  // the gradebook says so
    for (int lab : labs) {
      const nlohmann::json& entry = lab_entry(summary, lab);
      if (!entry.is_object()) continue;
      LabTally& t = tally[lab];
      ++t.submissions;
      const double max_score = entry.value("max_score", 0.0), score = entry.value("score", 0.0);
      const size_t bin = max_score <= 0.0 ? 0
                         : score >= max_score ? 10
                                              : std::min<size_t>(9, static_cast<size_t>(10.0 * score / max_score));
      ++t.bins[bin];
      if (entry["checks"].is_object())
        for (const auto& [key, check] : entry["checks"].items()) {
          auto [it, added] = t.checks.try_emplace(key, check.value("title", key), 0);
          if (added) t.check_order.push_back(key);
          it->second.second += check.value("passed", false) ? 1 : 0;
        }
      // Each probed function that differs (function_probes.h), once per submission; a pass by
      // its file, or its file and term (FunctionProbe::part: its function is main()).
      if (entry.contains("functions") && entry["functions"].is_array())
        for (const nlohmann::json& f : entry["functions"])
          if (f.value("status", std::string()) == kProbeDiffers) {
            const std::string function = f.value("part", f.value("function", std::string("?")));
            auto [it, added] = t.functions.try_emplace(function, f.value("file", std::string()), std::set<std::string>());
            it->second.second.insert(name);
          }
      const nlohmann::json& likely = entry["likely_mistakes"];
      if (likely.is_array() && !likely.empty()) {
        auto& m = t.mistakes[likely[0].value("id", std::string("?"))];
        m.first = likely[0].value("description", std::string());
        ++m.second;
      }
    }
  }

  std::string csv = "lab,what,key,title,count,submissions\n";
  std::string h = "<!doctype html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\n<title>kit-grade: the class</title>\n"
                  "<style>body{font:14px/1.4 sans-serif;margin:1.5em;max-width:60em}table{border-collapse:collapse}"
                  "td,th{border:1px solid #ccc;padding:2px 8px;text-align:left}td.n{text-align:right}"
                  ".bar{fill:#4a78b0}</style></head><body>\n<h1>What the class gets wrong</h1>\n"
                  "<p>From the summary.json of each submission in this folder (" + std::to_string(summaries.size()) +
                  " submissions); class-summary.csv holds the same counts.</p>\n";
  for (const auto& [lab, t] : tally) {
    const std::string of = std::to_string(t.submissions);
    h += "<h2>" + html_escape(lab_title(lab)) + "</h2>\n";
    // The distribution as bars, one per tenth of the lab's points.
    int most = 1;
    for (int n : t.bins) most = std::max(most, n);
    constexpr int kBarWidth = 40, kChartHeight = 120;
    h += "<svg role=\"img\" aria-label=\"score distribution of " + html_escape(lab_title(lab)) + "\" width=\"" +
         std::to_string(11 * kBarWidth) + "\" height=\"" + std::to_string(kChartHeight + 30) + "\">\n";
    for (size_t bin = 0; bin < t.bins.size(); ++bin) {
      const int height = t.bins[bin] * kChartHeight / most, x = static_cast<int>(bin) * kBarWidth;
      h += "<rect class=\"bar\" x=\"" + std::to_string(x + 4) + "\" y=\"" + std::to_string(kChartHeight - height) +
           "\" width=\"" + std::to_string(kBarWidth - 8) + "\" height=\"" + std::to_string(height) + "\"><title>" +
           bin_name(bin) + ": " + std::to_string(t.bins[bin]) + "</title></rect>";
      h += "<text x=\"" + std::to_string(x + kBarWidth / 2) + "\" y=\"" + std::to_string(kChartHeight + 14) +
           "\" text-anchor=\"middle\" font-size=\"11\">" + bin_name(bin) + "</text>";
      h += "<text x=\"" + std::to_string(x + kBarWidth / 2) + "\" y=\"" + std::to_string(kChartHeight + 27) +
           "\" text-anchor=\"middle\" font-size=\"11\">" + std::to_string(t.bins[bin]) + "</text>\n";
      csv += std::to_string(lab) + ",score," + bin_name(bin) + ",," + std::to_string(t.bins[bin]) + "," + of + "\n";
    }
    h += "</svg>\n<p>Scores in tenths of the lab's points; the last bar is full marks.</p>\n";
    h += "<table><tr><th>check</th><th>passed</th><th>of</th></tr>\n";
    for (const std::string& key : t.check_order) {
      const auto& [title, passed] = t.checks.at(key);
      h += "<tr><td>" + html_escape(title) + "</td><td class=\"n\">" + std::to_string(passed) + "</td><td class=\"n\">" +
           of + "</td></tr>\n";
      csv += std::to_string(lab) + ",check," + csv_field(key) + "," + csv_field(title) + "," + std::to_string(passed) + "," +
             of + "\n";
    }
    h += "</table>\n";
    if (!t.functions.empty()) {
      std::vector<std::pair<std::string, std::pair<std::string, std::set<std::string>>>> failing(t.functions.begin(),
                                                                                                 t.functions.end());
      std::stable_sort(failing.begin(), failing.end(),
                       [](const auto& a, const auto& b) { return a.second.second.size() > b.second.second.size(); });
      h += "<h3>Functions that differ from the reference solution's</h3>\n<table><tr><th>function</th><th>file</th>"
           "<th>submissions</th></tr>\n";
      for (const auto& [function, f] : failing) {
        const std::string count = std::to_string(f.second.size());
        // A pass by its file, or by its file and the term a probe isolates ("ibl.frag, diffuse").
        const std::string shown = function == f.first ? std::string("main() (the whole pass)")
                                  : function.rfind(f.first + ", ", 0) == 0 ? "main(): " + function.substr(f.first.size() + 2)
                                                                         : function;
        h += "<tr><td>" + html_escape(shown) + "</td><td>" +
             html_escape(f.first) + "</td><td class=\"n\">" + count +
             "</td></tr>\n";
        csv += std::to_string(lab) + ",function," + csv_field(function) + "," + csv_field(f.first) + "," + count + "," + of + "\n";
      }
      h += "</table>\n";
    }
    std::vector<std::pair<std::string, std::pair<std::string, int>>> named(t.mistakes.begin(), t.mistakes.end());
    std::stable_sort(named.begin(), named.end(), [](const auto& a, const auto& b) { return a.second.second > b.second.second; });
    if (!named.empty()) {
      h += "<h3>Likely mistakes, named first</h3>\n<table><tr><th>mistake</th><th>submissions</th></tr>\n";
      for (const auto& [id, m] : named) {
        h += "<tr><td>" + html_escape(m.first.empty() ? id : m.first) + "</td><td class=\"n\">" +
             std::to_string(m.second) + "</td></tr>\n";
        csv += std::to_string(lab) + ",mistake," + csv_field(id) + "," + csv_field(m.first) + "," +
               std::to_string(m.second) + "," + of + "\n";
      }
      h += "</table>\n";
    }
  }
  h += "</body></html>\n";
  write_file_atomic(dir / "class-summary.csv", csv);
  write_file_atomic(dir / "class-summary.html", h);
}

}  // namespace kit::grade
