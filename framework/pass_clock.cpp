#include "pass_clock.h"

#include <algorithm>
#include <map>

#include "gl.h"

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
  for (const std::string& pass : order) {
    std::vector<double>& v = samples[pass];
    std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
    medians.emplace_back(pass, v[v.size() / 2]);
  }
  return medians;
}

}  // namespace kit
