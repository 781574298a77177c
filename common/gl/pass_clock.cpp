#include "gl/pass_clock.h"

#include <algorithm>
#include <map>

#include "gl/gl.h"

namespace kit {

void PassClock::lap(const char* pass) {
  if (!out_) return;
  glFinish();
  const auto now = std::chrono::steady_clock::now();
  out_->emplace_back(pass, std::chrono::duration<double, std::milli>(now - start_).count());
  start_ = now;
}

PassTimes median_pass_times(const std::vector<PassTimes>& frames) {
  std::map<std::string, std::vector<double>> samples;
  std::vector<std::string> order;
  for (const PassTimes& frame : frames)
    for (const auto& [pass, ms] : frame) {
      if (!samples.count(pass)) order.push_back(pass);
      samples[pass].push_back(ms);
    }
  PassTimes medians;
  for (const std::string& pass : order) medians.emplace_back(pass, median(std::move(samples[pass])));
  return medians;
}

double median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2), values.end());
  return values[values.size() / 2];
}

}  // namespace kit
