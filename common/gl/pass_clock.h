#pragma once
// Where a frame's time goes: the wall-clock time of each pass, each ended by glFinish
// so the GPU's (or llvmpipe's) work is counted in the pass that issued it. The extra
// synchronisation slows the frame: for breakdowns (kit-render --timings, kit-bench
// --passes), never for the frame times the benchmarks report.
#include <chrono>
#include <string>
#include <utility>
#include <vector>

namespace kit {

// Seconds from `start` to now, on the steady clock every timing of the kit uses.
inline double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// (pass name, milliseconds) in the order the passes ran.
using PassTimes = std::vector<std::pair<std::string, double>>;

class PassClock {
 public:
  // With `out` null every lap() is a no-op, so a renderer can always call it.
  explicit PassClock(PassTimes* out) : out_(out), start_(std::chrono::steady_clock::now()) {}
  // Ends the pass named `pass`: glFinish, then its time since the last lap (or the start).
  void lap(const char* pass);

 private:
  PassTimes* out_;
  std::chrono::steady_clock::time_point start_;
};

// Per pass, the median over frames of its times, in the order passes first ran.
PassTimes median_pass_times(const std::vector<PassTimes>& frames);
// The middle value (the upper one of an even count); 0 for none.
double median(std::vector<double> values);

}  // namespace kit
