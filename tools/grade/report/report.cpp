#include "report/report.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include "base/error.h"
#include "files/files.h"
#include "render/stages.h"
#include "verdict/diagnosis.h"
#include "verdict/lab_verdict.h"

namespace fs = std::filesystem;

namespace kit::grade {

namespace {

// A lab's problem text is cut to this many bytes in results.json (report.html has it all).
constexpr size_t kMaxMessageBytes = 8 * 1024;
constexpr const char* kLeaderboardName = "render time (ms)";

// Said where a submission was rendered outside the implementations the tolerances were
// measured on: its verdict is likely right, but not checked there.
std::string outside_measured_note(const SubmissionOutcome& s) {
  return "Rendered outside the OpenGL implementations the tolerances were measured on (" +
         (s.measured_on.empty() ? std::string("none listed") : s.measured_on) +
         "): a correct lab is expected to keep full marks here too, but that was not measured "
         "(docs/grading.md, The same grade on any computer).";
}

// --gpu: said in every report, whatever rendered, since the choice was the grader's.
std::string gpu_note(const SubmissionOutcome& s) {
  return "Graded with --gpu: rendered by " + (s.renderer.empty() ? std::string("the first device") : s.renderer) +
         " on purpose, not by Mesa's software rasteriser that official grades use; where that is not one of the "
         "implementations the tolerances were measured on, the verdict comes from outside them.";
}

const char* status_words(const std::string& status) {
  if (status == kCompileError) return "compile error";
  if (status == kTimeout) return "timed out";
  if (status == kCrash) return "renderer crashed";
  if (status == kNonFiniteMap) return "NaN or Inf in a precomputed map";
  if (status == kMissingFiles) return "files missing";
  if (status == kInvalidFiles) return "files refused";
  if (status == kGraderError) return "grader error";
  return "graded";
}

// The line of a message worth one line of console: the first compiler error
// ("labs/02-lighting/brdf.glsl:12:3: error: ..."), else the first line (with
// the next one when it ends in ':', as "link error (a + b):" does).
std::string headline(const std::string& text) {
  std::vector<std::string> lines;
  size_t start = 0;
  while (start < text.size()) {
    size_t end = text.find('\n', start);
    lines.push_back(text.substr(start, end == std::string::npos ? std::string::npos : end - start));
    if (lines.back().find("error:") != std::string::npos) return lines.back();
    if (end == std::string::npos) break;
    start = end + 1;
  }
  if (lines.empty()) return "";
  if (lines.size() > 1 && !lines[0].empty() && lines[0].back() == ':') return lines[0] + " " + lines[1];
  return lines[0];
}

std::string truncated(const std::string& text) {
  if (text.size() <= kMaxMessageBytes) return text;
  // Cut at a line end, and never inside a UTF-8 sequence.
  size_t cut = text.rfind('\n', kMaxMessageBytes);
  if (cut == std::string::npos) {
    cut = kMaxMessageBytes;
    while (cut > 0 && (static_cast<unsigned char>(text[cut]) & 0xC0) == 0x80) --cut;
  }
  return text.substr(0, cut) + "\n[... cut; report.html has the whole message]";
}

// Markdown: student text in a fenced block whose fence no backtick run in the text can close.
std::string md_code(const std::string& text) {
  size_t longest = 0, run = 0;
  for (char c : text) {
    run = c == '`' ? run + 1 : 0;
    longest = std::max(longest, run);
  }
  std::string fence(std::max<size_t>(3, longest + 1), '`');
  return fence + "\n" + text + (text.empty() || text.back() == '\n' ? "" : "\n") + fence + "\n";
}

// Markdown outside code: escape what could format text, link, or inject HTML
// (numbers and parentheses stay readable; a note never starts a line with # or -).
std::string md_escape(const std::string& text) {
  std::string out;
  for (char c : text) {
    if (c == '<') out += "&lt;";
    else if (c == '>') out += "&gt;";
    else if (c == '&') out += "&amp;";
    else if (std::string("\\`*_[]|~").find(c) != std::string::npos) out += std::string("\\") + c;
    else out += c;
  }
  return out;
}

std::string check_name(const CheckOutcome& c) { return lab_title(c.check->lab) + ": " + c.check->title; }

// Where the lab's handout lists its common mistakes.
std::string common_mistakes_link(int lab) { return "handouts/" + find_stage(lab).folder + ".md#common-mistakes"; }

// "Looks like: A (similarity 0.97); or: B (similarity 0.81). See handouts/...", or that
// none fits.
std::string likely_text(const LabOutcome& lab) {
  if (!lab.diagnosed) return "";
  if (lab.likely_mistakes.empty()) return "No catalogued mistake fits these images closely.";
  std::string out = "Looks like: ";
  for (size_t i = 0; i < lab.likely_mistakes.size(); ++i) {
    const LikelyMistake& m = lab.likely_mistakes[i];
    char similarity[32];
    std::snprintf(similarity, sizeof similarity, "%.2f", m.similarity);
    out += (i ? "; or: " : "") + m.description + " (similarity " + similarity + ")";
  }
  return out + ". See " + common_mistakes_link(lab.lab) + ".";
}

nlohmann::json functions_json(const LabOutcome& lab) {
  nlohmann::json out = nlohmann::json::array();
  for (const ProbeOutcome& p : lab.probes) out.push_back(probe_outcome_json(p));
  return out;
}

// The lab's probe feedback (function_probes.h) where a check failed.
std::vector<std::string> functions_lines(const LabOutcome& lab) {
  const bool failed = std::any_of(lab.checks.begin(), lab.checks.end(), [](const CheckOutcome& c) { return c.compared && !c.passed; });
  return probe_feedback(lab.probes, failed);
}

// `first`: the lab's first check (a lab not graded says why there); `functions`: the lab's
// first failed check, which lists the probed functions that differ.
std::string check_markdown(const LabOutcome& lab, const CheckOutcome& c, bool first, bool functions) {
  if (!c.compared) {
    std::string out = std::string("**Not graded: ") + status_words(lab.status) + ".**\n\n";
    if (first) return out + md_code(truncated(lab.message));
    return out + "See the first test of " + lab_title(lab.lab) + " for the message.\n";
  }
  std::string out = c.passed ? "Passed. " : "**Failed.** ";
  if (!c.comparison.note.empty()) out += md_escape(c.comparison.note) + "\n\n";
  out += md_escape(c.comparison.summary) + ".\n";
  if (!c.comparison.worst_pixel.empty()) out += "\nAt " + md_escape(c.comparison.worst_pixel) + ".\n";
  if (!c.passed && lab.diagnosed) out += "\n" + md_escape(likely_text(lab)) + "\n";
  if (functions)
    for (const std::string& line : functions_lines(lab)) out += "\n* " + md_escape(line) + "\n";
  return out;
}

double rounded(double v) { return std::round(v * 1000.0) / 1000.0; }

}  // namespace

std::string lab_title(int lab) {
  const Stage& s = find_stage(lab);
  return "lab " + std::to_string(s.number) + " " + s.name;
}

std::string format_points(Thousandths points) {
  // Exact: the integer and its thousandths, trailing zeros dropped (6.667, 6.5, 10).
  const bool negative = points < 0;
  const Thousandths magnitude = negative ? -points : points;
  std::string s = std::to_string(magnitude / 1000);
  Thousandths fraction = magnitude % 1000;
  if (fraction != 0) {
    char buf[8];
    std::snprintf(buf, sizeof buf, ".%03lld", static_cast<long long>(fraction));
    std::string f = buf;
    while (f.back() == '0') f.pop_back();
    s += f;
  }
  return negative ? "-" + s : s;
}

double points_value(Thousandths points) { return static_cast<double>(points) / 1000.0; }

Thousandths points_from_value(double value) { return static_cast<Thousandths>(std::llround(value * 1000.0)); }

std::string format_score(double score) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.2f", score);
  std::string s = buf;
  while (s.back() == '0') s.pop_back();
  if (s.back() == '.') s.pop_back();
  return s;
}

std::string lab_line(const LabOutcome& lab) {
  std::string line = lab_title(lab.lab) + ": " + format_points(lab.score()) + "/" + format_points(lab.max_score()) + "  (";
  if (lab.status == kGraded)
    return line + std::to_string(lab.passed_checks()) + " of " + std::to_string(lab.checks.size()) + " checks passed)";
  return line + status_words(lab.status) + ": " + headline(lab.message) + ")";
}

std::string html_escape(const std::string& text) {
  std::string out;
  for (char c : text) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      case '\'': out += "&#39;"; break;
      default: out += c;
    }
  }
  return out;
}

nlohmann::json results_json(const SubmissionOutcome& s) {
  nlohmann::json tests = nlohmann::json::array();
  double render_ms = 0.0;
  for (const auto& [number, lab] : s.labs) {
    render_ms += lab.render_ms;
    bool first = true, functions_shown = false;
    for (const CheckOutcome& c : lab.checks) {
      const bool functions = c.compared && !c.passed && !functions_shown;
      functions_shown = functions_shown || functions;
      tests.push_back({{"name", check_name(c)},
                       {"score", points_value(c.score)},
                       {"max_score", points_value(c.max_score)},
                       {"status", c.passed ? "passed" : "failed"},
                       {"output", check_markdown(lab, c, first, functions)},
                       {"output_format", "md"},
                       {"visibility", "visible"}});
      first = false;
    }
  }
  std::string output = "**Total: " + format_points(s.total()) + " / " + format_points(s.max_total()) + "**";
  if (!s.renderer.empty()) output += " (rendered with " + md_escape(s.renderer) + ")";
  if (s.gpu) output += "\n\n" + md_escape(gpu_note(s));
  if (!s.renderer.empty() && !s.within_measured) output += "\n\n" + md_escape(outside_measured_note(s));
  output += "\n\n| Lab | Score | Result |\n|---|---|---|\n";
  for (const auto& [number, lab] : s.labs) {
    std::string result = lab.status == kGraded ? std::to_string(lab.passed_checks()) + " of " +
                                                     std::to_string(lab.checks.size()) + " checks passed"
                                               : status_words(lab.status);
    output += "| " + lab_title(number) + " | " + format_points(lab.score()) + " / " + format_points(lab.max_score()) + " | " + result + " |\n";
  }
  if (!s.problem.empty()) output += "\n**The submission could not be graded:**\n\n" + md_code(s.problem);
  for (const std::string& note : s.notes) output += "\n* " + md_escape(note);
  return {{"score", points_value(s.total())},
          {"execution_time", rounded(s.seconds)},
          {"output", output},
          {"output_format", "md"},
          {"visibility", "visible"},
          {"stdout_visibility", "hidden"},
          {"tests", tests},
          {"leaderboard", nlohmann::json::array({{{"name", kLeaderboardName}, {"value", rounded(render_ms)}, {"order", "asc"}}})}};
}

nlohmann::json summary_json(const SubmissionOutcome& s) {
  nlohmann::json labs = nlohmann::json::object();
  for (const auto& [number, lab] : s.labs) {
    nlohmann::json checks = nlohmann::json::object();
    for (const CheckOutcome& c : lab.checks) {
      nlohmann::json entry = {{"title", c.check->title}, {"passed", c.passed}, {"score", points_value(c.score)},
                              {"max_score", points_value(c.max_score)}};
      if (c.compared) {
        entry["summary"] = c.comparison.summary;
        entry["note"] = c.comparison.note;
        if (!c.comparison.worst_pixel.empty()) entry["worst_pixel"] = c.comparison.worst_pixel;
        entry["image"] = c.image;
        entry["reference"] = c.reference;
        entry["diff"] = c.diff;
        entry["max_error"] = c.comparison.max_error;
        entry["failing_percent"] = c.comparison.failing_percent;
        entry["failing_pixels"] = c.comparison.failing_pixels;
        entry["allowed_failing_pixels"] = c.comparison.allowed_failing_pixels;
        entry["covered_pixels"] = c.comparison.covered_pixels;
        entry["covered_mean_error"] = c.comparison.covered_mean_error;
        entry["edge_pixels"] = c.comparison.edge_pixels;
        entry["psnr"] = std::isfinite(c.comparison.psnr) ? nlohmann::json(c.comparison.psnr) : nlohmann::json(nullptr);
        entry["non_finite"] = c.comparison.non_finite;
        nlohmann::json signature = nlohmann::json::array();
        for (float v : c.comparison.signature) signature.push_back(std::round(v * 1000.0f) / 1000.0f);
        entry["signature"] = signature;
      }
      checks[c.check->key] = entry;
    }
    labs[std::to_string(number)] = {
        {"name", find_stage(number).name},
        {"score", points_value(lab.score())},
        {"max_score", points_value(lab.max_score())},
        {"status", lab.status},
        {"message", lab.message},
        {"folder", lab.folder},
        {"checks_passed", lab.passed_checks()},
        {"checks", checks},
        {"likely_mistakes", likely_mistakes_json(lab.likely_mistakes)},
        {"likely_text", likely_text(lab)},  // the sentence the report shows, for the platforms' own results
        {"functions", functions_json(lab)},
        {"functions_text", functions_lines(lab)},
        {"evidence", lab.evidence},
        {"render_ms", rounded(lab.render_ms)},
        {"seconds", {{"child_wall", rounded(lab.child_seconds)}, {"child_cpu", rounded(lab.child_cpu_seconds)},
                     {"compare", rounded(lab.compare_seconds)}}},
        {"child_timings", lab.child_timings},
        {"child_max_rss_kib", lab.child_max_rss_kib},
        {"child_vm_peak_kib", lab.child_vm_peak_kib}};
  }
  return {{"submission", s.name},
          {"labs", labs},
          {"total", points_value(s.total())},
          {"max_total", points_value(s.max_total())},
          {"problem", s.problem},
          {"notes", s.notes},
          {"content_hash", s.content_hash},
          {"renderer", s.renderer},
          {"references_renderer", s.references_renderer},
          {"tolerances_measured_on", s.measured_on},
          {"within_measured_implementations", s.within_measured},
          // Which device rendered: "software" (Mesa's software rasteriser, chosen explicitly: OSMesa
          // or EGL's EGL_MESA_device_software device) or "gpu" (--gpu: the platform's first device).
          {"device", s.gpu ? "gpu" : "software"},
          {"execution_time", rounded(s.seconds)}};
}

std::string report_html(const SubmissionOutcome& s) {
  std::string h;
  h += "<!doctype html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\n<title>kit-grade: " + html_escape(s.name) + "</title>\n";
  h += "<style>\n"
       "body{font-family:sans-serif;margin:1.5em;color:#222}\n"
       "table{border-collapse:collapse}td,th{border:1px solid #ccc;padding:4px 8px;vertical-align:top;text-align:left}\n"
       "tr.failed td:first-child{border-left:6px solid #c33}tr.passed td:first-child{border-left:6px solid #3a3}\n"
       "pre{background:#f4f4f4;padding:8px;overflow-x:auto;max-width:100em}\n"
       "img{display:block;width:256px;image-rendering:pixelated}\n"
       ".swap{position:relative;width:256px}.swap .ref{position:absolute;left:0;top:0;opacity:0}\n"
       ".swap:hover .ref{opacity:1}.numbers{max-width:28em;font-size:90%}.note{color:#a00}\n"
       ".spot{position:relative;width:256px}.worst{position:absolute;width:12px;height:12px;margin:-8px 0 0 -8px;"
       "border:2px solid #0f0;border-radius:50%;box-shadow:0 0 0 1px #000;pointer-events:none}\n"
       "</style></head><body>\n";
  h += "<h1>" + html_escape(s.name) + ": " + format_points(s.total()) + " / " + format_points(s.max_total()) + "</h1>\n";
  h += "<p>Rendered with " + html_escape(s.renderer.empty() ? std::string("(nothing rendered)") : s.renderer) + " at " +
       std::to_string(kGradeWidth) + "x" + std::to_string(kGradeHeight) + " in " + format_score(s.seconds) +
       " s. Hover a submission image to see the reference; the diff shows |submission - reference| &times; " +
       format_score(kDiffScale) + ", a green ring on it the worst pixel of a failed check.</p>\n";
  h += "<p>References rendered with " + html_escape(s.references_renderer.empty() ? "(unknown)" : s.references_renderer) +
       "; tolerances measured on " + html_escape(s.measured_on.empty() ? "(none listed)" : s.measured_on) + ".</p>\n";
  if (s.gpu) h += "<p class=\"note\">" + html_escape(gpu_note(s)) + "</p>\n";
  if (!s.renderer.empty() && !s.within_measured) h += "<p class=\"note\">" + html_escape(outside_measured_note(s)) + "</p>\n";
  if (!s.problem.empty()) h += "<h2>The submission could not be graded</h2>\n<pre>" + html_escape(s.problem) + "</pre>\n";
  if (!s.notes.empty()) {
    h += "<ul>\n";
    for (const std::string& n : s.notes) h += "<li>" + html_escape(n) + "</li>\n";
    h += "</ul>\n";
  }
  h += "<table><tr><th>Lab</th><th>Score</th><th>Result</th></tr>\n";
  for (const auto& [number, lab] : s.labs)
    h += "<tr class=\"" + std::string(lab.score() == lab.max_score() ? "passed" : "failed") + "\"><td>" +
         html_escape(lab_title(number)) + "</td><td>" + format_points(lab.score()) + " / " + format_points(lab.max_score()) +
         "</td><td>" + html_escape(lab_line(lab)) + "</td></tr>\n";
  h += "</table>\n";
  for (const auto& [number, lab] : s.labs)
    if (lab.status != kGraded)
      h += "<h2>" + html_escape(lab_title(number)) + ": " + status_words(lab.status) + "</h2>\n<pre>" +
           html_escape(lab.message) + "</pre>\n";
  for (const auto& [number, lab] : s.labs)
    if (lab.diagnosed)
      h += "<p class=\"likely\"><b>" + html_escape(lab_title(number)) + "</b>: " + html_escape(likely_text(lab)) + "</p>\n";
  // The probed functions: what differs, with the first inputs where it does.
  for (const auto& [number, lab] : s.labs) {
    if (lab.probes.empty()) continue;
    h += "<h2>" + html_escape(lab_title(number)) + ": your functions</h2>\n<table><tr><th>Function</th><th>File</th><th>Result</th></tr>\n";
    for (const ProbeOutcome& p : lab.probes)
      h += "<tr class=\"" + std::string(p.status == kProbeDiffers ? "failed" : "passed") + "\"><td>" +
           html_escape(p.probe->title()) + "</td><td>" + html_escape(p.probe->file) + "</td><td>" +
           html_escape(p.status == kProbeAgrees ? "agrees with the reference solution at all " + std::to_string(p.total) + " inputs"
                                                : p.message) +
           "</td></tr>\n";
    h += "</table>\n";
  }

  std::vector<std::pair<const LabOutcome*, const CheckOutcome*>> rows;
  for (const auto& [number, lab] : s.labs)
    for (const CheckOutcome& c : lab.checks) rows.push_back({&lab, &c});
  std::stable_sort(rows.begin(), rows.end(), [](const auto& a, const auto& b) { return !a.second->passed && b.second->passed; });
  h += "<h2>Checks</h2>\n<table><tr><th>Check</th><th>Submission</th><th>Reference</th><th>Diff</th><th>Numbers</th></tr>\n";
  for (const auto& [lab, c] : rows) {
    h += "<tr class=\"" + std::string(c->passed ? "passed" : "failed") + "\"><td>" + html_escape(check_name(*c)) +
         "<br><b>" + (c->passed ? "passed" : "failed") + "</b> " + format_points(c->score) + " / " + format_points(c->max_score) + "</td>";
    if (!c->compared) {
      h += "<td colspan=\"4\">not rendered: " + std::string(status_words(lab->status)) + "</td></tr>\n";
      continue;
    }
    std::string alt = html_escape(c->check->title);
    h += "<td><div class=\"swap\"><img src=\"" + html_escape(c->image) + "\" alt=\"submission: " + alt + "\">" +
         "<img class=\"ref\" src=\"" + html_escape(c->reference) + "\" alt=\"reference\"></div></td>";
    h += "<td><img src=\"" + html_escape(c->reference) + "\" alt=\"reference: " + alt + "\"></td>";
    // The worst pixel ringed on the difference, where the numbers name it.
    const Comparison& cmp = c->comparison;
    std::string ring;
    if (!cmp.worst_pixel.empty() && cmp.width > 0 && cmp.height > 0) {
      char style[96];
      std::snprintf(style, sizeof style, "left:%.2f%%;top:%.2f%%", 100.0 * (cmp.max_x + 0.5) / cmp.width,
                    100.0 * (cmp.max_y + 0.5) / cmp.height);
      ring = "<span class=\"worst\" style=\"" + std::string(style) + "\" title=\"the worst pixel, (" +
             std::to_string(cmp.max_x) + ", " + std::to_string(cmp.max_y) + ")\"></span>";
    }
    h += "<td><div class=\"spot\"><img src=\"" + html_escape(c->diff) + "\" alt=\"difference\">" + ring + "</div></td>";
    h += "<td class=\"numbers\">";
    if (!c->comparison.note.empty()) h += "<p class=\"note\">" + html_escape(c->comparison.note) + "</p>";
    h += html_escape(c->comparison.summary);
    if (!c->comparison.worst_pixel.empty()) h += "<p>At " + html_escape(c->comparison.worst_pixel) + ".</p>";
    h += "</td></tr>\n";
  }
  h += "</table>\n";
  // The free-choice effect is not graded beyond its toggle: shown large for the instructor.
  for (const auto& [lab, c] : rows)
    if (c->compared && c->check->metric == Metric::Changes)
      h += "<h2>" + html_escape(lab_title(lab->lab)) + ": the free-choice effect (on)</h2>\n<img src=\"" +
           html_escape(c->image) + "\" alt=\"custom effect\" style=\"width:512px\">\n";
  h += "</body></html>\n";
  return h;
}

nlohmann::json likely_mistakes_json(const std::vector<LikelyMistake>& mistakes) {
  nlohmann::json out = nlohmann::json::array();
  for (const LikelyMistake& m : mistakes)
    out.push_back({{"id", m.id}, {"description", m.description}, {"similarity", std::round(m.similarity * 1000.0) / 1000.0}});
  return out;
}

void write_results(const fs::path& dir, const SubmissionOutcome& outcome) {
  write_file_atomic(dir / "report.html", report_html(outcome));
  write_file_atomic(dir / "summary.json", json_text(summary_json(outcome)));
  // What each failed lab's likely mistakes were named from, for --name-again (diagnosis.h).
  nlohmann::json naming = nlohmann::json::object();
  for (const auto& [number, lab] : outcome.labs)
    if (needs_naming(lab)) naming[std::to_string(number)] = naming_inputs_json(naming_inputs(lab));
  // None: no earlier grading's file may stay in a folder graded again (--out reused, a batch's --force).
  std::error_code ec;
  if (naming.empty()) fs::remove(dir / kNamingInputsFile, ec);
  else write_file_atomic(dir / kNamingInputsFile, json_text(naming));
  // Last: its presence marks a complete result (batch resumes on it).
  write_file_atomic(dir / "results.json", json_text(results_json(outcome)));
}

}  // namespace kit::grade
