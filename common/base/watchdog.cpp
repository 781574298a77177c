#include "base/watchdog.h"

#include <unistd.h>

#include <cstdio>

namespace kit {

Watchdog::Watchdog(std::string tool, double seconds, std::string advice)
    : tool_(std::move(tool)), advice_(std::move(advice)), seconds_(seconds) {
  if (seconds_ > 0.0) thread_ = std::thread([this] { watch(); });
}

Watchdog::~Watchdog() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
  }
  changed_.notify_all();
  if (thread_.joinable()) thread_.join();
}

void Watchdog::arm(const std::string& activity) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    activity_ = activity;
    deadline_ = std::chrono::steady_clock::now() +
                std::chrono::duration_cast<std::chrono::steady_clock::duration>(std::chrono::duration<double>(seconds_));
    armed_ = true;
  }
  changed_.notify_all();
}

void Watchdog::relabel(const std::string& activity) {
  std::lock_guard<std::mutex> lock(mutex_);
  activity_ = activity;
}

void Watchdog::disarm() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    armed_ = false;
  }
  changed_.notify_all();
}

std::string Watchdog::message(const std::string& activity) const {
  char seconds[32];
  std::snprintf(seconds, sizeof seconds, "%g", seconds_);
  return tool_ + ": timed out after " + seconds + " s " + activity + ": does a shader loop forever?" +
         (advice_.empty() ? "" : " " + advice_);
}

void Watchdog::watch() {
  std::unique_lock<std::mutex> lock(mutex_);
  while (!stopping_) {
    if (!armed_) {
      changed_.wait(lock);
      continue;
    }
    if (std::chrono::steady_clock::now() < deadline_) {
      changed_.wait_until(lock, deadline_);
      continue;  // woken early, re-armed or disarmed: look again
    }
    // Past the deadline and still armed: the GL call is not coming back.
    std::string line = message(activity_) + "\n";
    ssize_t written = ::write(STDERR_FILENO, line.data(), line.size());
    (void)written;  // nothing more can be done if stderr is gone
    _exit(kTimedOutStatus);
  }
}

}  // namespace kit
