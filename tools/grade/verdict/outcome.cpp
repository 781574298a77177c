#include "verdict/outcome.h"

#include <algorithm>

namespace kit::grade {

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

Thousandths SubmissionOutcome::total() const {
  Thousandths sum = 0;
  for (const auto& [n, lab] : labs) sum += lab.score();
  return sum;
}

Thousandths SubmissionOutcome::max_total() const {
  Thousandths sum = 0;
  for (const auto& [n, lab] : labs) sum += lab.max_score();
  return sum;
}

bool SubmissionOutcome::grader_error() const {
  return std::any_of(labs.begin(), labs.end(), [](const auto& l) { return l.second.status == kGraderError; });
}

}  // namespace kit::grade
