#include "lab_verdict.h"

#include <algorithm>

#include "render/renderer.h"
#include "lab_frames.h"

namespace kit::grade {

LabOutcome lab_outcome(const Config& config, int lab) {
  LabOutcome out;
  out.lab = lab;
  for (const Check* check : lab_checks(lab)) {
    CheckOutcome c;
    c.check = check;
    c.max_score = config.max_score(*check);
    out.checks.push_back(c);
  }
  return out;
}

namespace {

// Lab 7's work check: the frame's counted work against its limits, credited only where the
// frame's image check (earlier in the list) passed.
Comparison compare_work_check(const Config& config, const LabOutcome& lab, const CheckOutcome& c,
                              const nlohmann::json& child, const Image& image) {
  const CheckOutcome* shown = nullptr;
  for (const CheckOutcome& other : lab.checks)
    if (&other != &c && other.compared && other.check->image == c.check->image && other.check->metric != Metric::Work)
      shown = &other;
  const nlohmann::json counted = child.contains("work") ? child["work"].value(c.check->image, nlohmann::json()) : nlohmann::json();
  Comparison r = compare_work(config.tolerance(*c.check), work_from_json(counted), shown && shown->passed,
                              shown ? shown->check->key : c.check->image, image.width, image.height);
  if (counted.is_object()) r.summary += "; state " + counted.value("state", std::string("?"));
  return r;
}

}  // namespace

void compare_check(const Config& config, LabOutcome& lab, CheckOutcome& c, const std::map<std::string, Image>& renders,
                   const nlohmann::json& child, const StoredReference& stored) {
  const Check& check = *c.check;
  const Image& image = renders.at(check.image);
  const bool own = compares_own_renders(check.metric);  // its "reference" is the submission's own render
  if (check.metric == Metric::Work) {
    c.comparison = compare_work_check(config, lab, c, child, image);
  } else {
    const Image& reference = own ? renders.at(check.reference) : *stored.image;
    const Background* background = own ? nullptr : stored.background;
    const Image* allowance = !own && stored.allowance && stored.allowance->width > 0 ? stored.allowance : nullptr;
    c.comparison = compare_images(check.metric, config.tolerance(check), image, reference, background, allowance);
  }
  const size_t hdr_bad = child.contains("hdr_non_finite") ? child["hdr_non_finite"].value(check.image, size_t{0}) : 0;
  if (hdr_bad > 0 && !own) {
    c.comparison.passed = false;
    c.comparison.note = "the HDR buffer behind this image holds " + std::to_string(hdr_bad) +
                        " NaN or Inf pixels: " + kNonFiniteAdvice;
  }
  c.compared = true;
  c.passed = c.comparison.passed;
  c.score = c.passed ? c.max_score : 0;
}

Metric shown_metric(const Check& check) {
  return check.metric == Metric::Work ? Metric::Hdr : compares_own_renders(check.metric) ? Metric::Ldr : check.metric;
}

void name_likely_mistakes(const MistakeSignatures& mistakes, LabOutcome& lab) {
  if (mistakes.empty() || lab.passed_checks() >= static_cast<int>(lab.checks.size())) return;
  std::map<std::string, std::vector<float>> signatures;
  for (const CheckOutcome& c : lab.checks) signatures[c.check->key] = check_features(c.comparison.signature, !c.passed);
  lab.likely_mistakes = likely_mistakes(mistakes, lab.lab, signatures);
  lab.diagnosed = true;
}

int LabOutcome::passed_checks() const {
  return static_cast<int>(std::count_if(checks.begin(), checks.end(), [](const CheckOutcome& c) { return c.passed; }));
}

Thousandths LabOutcome::score() const {
  Thousandths sum = 0;
  for (const CheckOutcome& c : checks) sum += c.score;
  return sum;
}

Thousandths LabOutcome::max_score() const {
  Thousandths sum = 0;
  for (const CheckOutcome& c : checks) sum += c.max_score;
  return sum;
}

}  // namespace kit::grade
