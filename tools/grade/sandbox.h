#pragma once
// Child processes under limits: each runs in its own process group (so a
// timeout kills it and every thread or helper it started), with rlimits on CPU
// time, address space and written file size, stdout+stderr to a log file.
//
// Render children are fork()ed without exec(): kit-grade links OpenImageIO,
// whose ~260 shared libraries cost ~0.3 s of CPU and ~130 MB of RSS per exec
// (measured by instructor/grading/measure.sh), more than rendering a lab. What makes
// that safe: the parent never creates a GL context, does all its own work in
// one thread (OpenImageIO "threads" = 1, OpenEXR without a pool; the only other
// threads are log4cplus's idle pool, started when a dependency of OpenImageIO
// loads, and never used), and a child only renders with a fresh context, writes
// raw files and leaves with _exit(), running none of the parent's destructors.
#include <signal.h>
#include <sys/resource.h>
#include <sys/types.h>

#include <chrono>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "watchdog.h"

namespace kit::grade {

struct Limits {
  double wall_seconds = kDefaultTimeoutSeconds;  // --timeout: wall clock, then SIGKILL to the process group
  rlim_t cpu_seconds = 60;     // --cpu-limit: RLIMIT_CPU (llvmpipe's threads add up)
  rlim_t address_space_mib = 4096;  // --memory-limit: RLIMIT_AS (llvmpipe reserves ~1 GiB of address space)
  rlim_t file_size_mib = 64;   // RLIMIT_FSIZE: a lab's raw images are ~8 MiB
};

struct Outcome {
  enum class Kind { Running, Exited, Signaled, TimedOut };
  Kind kind = Kind::Running;
  int code = 0;           // exit status, or the signal number
  double wall_seconds = 0.0;
  double cpu_seconds = 0.0;  // user + system, from wait4
  long max_rss_kib = 0;      // peak resident set, from wait4
  std::string describe() const;  // "exit 2", "signal 11 (Segmentation fault)", "timed out after 30 s"
};

class Child {
 public:
  // Runs `body` in a forked child; its return value is the exit status.
  static Child fork_function(const std::function<int()>& body, const Limits& limits, const std::filesystem::path& log);
  // Runs a program (looked up in PATH) with `args` (args[0] is the program).
  static Child exec_program(const std::vector<std::string>& args, const Limits& limits, const std::filesystem::path& log);

  Child(Child&& other) noexcept;
  Child& operator=(Child&&) = delete;
  Child(const Child&) = delete;
  ~Child();  // kills and reaps a child still running

  // Non-blocking: reaps the child if it ended, kills its group past the wall limit.
  // True once the outcome is final.
  bool poll();
  // Blocks until the outcome is final.
  const Outcome& wait();
  const Outcome& outcome() const { return outcome_; }
  pid_t pid() const { return pid_; }

 private:
  Child(pid_t pid, double wall_seconds);
  void reap(int status, const rusage& usage);
  pid_t pid_ = -1;
  double wall_limit_ = 0.0;
  bool killed_for_time_ = false;
  std::chrono::steady_clock::time_point started_;
  Outcome outcome_;
};

// Blocks SIGINT and SIGTERM for its lifetime so the polling loop can notice
// them (pending()) and stop its children cleanly instead of orphaning them in
// their own process groups. Children unblock them again.
class InterruptGuard {
 public:
  InterruptGuard();
  ~InterruptGuard();
  InterruptGuard(const InterruptGuard&) = delete;
  InterruptGuard& operator=(const InterruptGuard&) = delete;
  int pending() const;  // the signal number when one arrived, else 0 (consumes it)

 private:
  sigset_t blocked_{}, previous_{};
};

// Sleeps briefly between polls of running children (a few milliseconds).
void poll_pause();

// The last `max_bytes` of a (log) file, or "" when unreadable.
std::string read_tail(const std::filesystem::path& path, size_t max_bytes);

}  // namespace kit::grade
