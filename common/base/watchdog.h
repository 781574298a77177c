#pragma once
// A time limit for GL work that may never return. A shader that loops forever
// blocks the GL call that waits for it (glFinish, a read-back, a buffer swap),
// so the thread that made the call can report nothing. The watchdog's own
// thread waits for the deadline and, past it, prints
//   "TOOL: timed out after N s ACTIVITY: does a shader loop forever?"
// on stderr and ends the process with kTimedOutStatus. It ends it with _exit:
// the stuck call holds the GL driver's locks, so no destructor may run.
// kit-render and kit-view use it (--timeout); the grader's sandbox stops its
// render workers from outside: after the same number of seconds of CPU time
// (RLIMIT_CPU), with a longer wall-clock backstop.
#include <chrono>
#include <condition_variable>
#include <mutex>
#include <string>
#include <thread>

namespace kit {

constexpr int kTimedOutStatus = 124;             // as timeout(1) exits
constexpr double kDefaultTimeoutSeconds = 30.0;  // kit-render and kit-view's --timeout (kit-grade: --cpu-limit 30)

class Watchdog {
 public:
  // `tool` starts the message ("kit-render"); `advice` follows the question
  // when not empty. seconds <= 0: the watchdog never fires.
  Watchdog(std::string tool, double seconds, std::string advice = "");
  ~Watchdog();
  Watchdog(const Watchdog&) = delete;
  Watchdog& operator=(const Watchdog&) = delete;

  // Starts the clock for `activity` ("rendering stage gbuffer").
  void arm(const std::string& activity);
  // Names what is going on now; the clock keeps running.
  void relabel(const std::string& activity);
  void disarm();

  double seconds() const { return seconds_; }
  // The line it prints when it fires for `activity` (no newline).
  std::string message(const std::string& activity) const;

 private:
  void watch();

  const std::string tool_, advice_;
  const double seconds_;
  std::mutex mutex_;
  std::condition_variable changed_;
  std::chrono::steady_clock::time_point deadline_;
  std::string activity_;
  bool armed_ = false, stopping_ = false;
  std::thread thread_;
};

}  // namespace kit
