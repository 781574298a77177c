#pragma once
// Child processes under limits: each runs in a session and process group of its
// own (so a timeout kills it and every thread or helper it started, and it has
// no controlling terminal to read a password from), in a working directory of
// the grader's temporary folder, with rlimits on CPU time, address space,
// written file size, open files and processes, stdout+stderr to a log file.
//
// Time: RLIMIT_CPU is the limit (CPU time does not grow when the machine is
// busy, so a heavy but valid shader is not stopped by other load); the wall
// clock is a larger backstop for a child that makes no progress without using
// CPU. Memory: RLIMIT_AS; a child that dies for lack of it (std::bad_alloc, or
// a signal or failure with its peak address space at the limit) ends as
// Outcome::Kind::OutOfMemory, not as a crash.
//
// Render workers are fork()ed without exec(): the scenes are loaded once, in the
// parent, and a worker starts rendering at once. What makes that safe: the parent never
// creates a GL context, does all its own work in one thread (OpenEXR without worker
// threads; OpenImageIO, whose dependencies start threads of their own, is never loaded
// by a grading run: openimageio_formats.h), and a worker only renders with a context of
// its own, writes raw files and leaves with _exit(), running none of the parent's
// destructors.
#include <signal.h>
#include <sys/resource.h>
#include <sys/types.h>

#include <chrono>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace kit::grade {

// Defaults of kit-grade's --cpu-limit and --timeout.
constexpr rlim_t kDefaultCpuSeconds = 30;
constexpr double kDefaultWallSeconds = 120.0;

struct Limits {
  double wall_seconds = kDefaultWallSeconds;  // --timeout: wall-clock backstop, then SIGKILL to the process group
  rlim_t cpu_seconds = kDefaultCpuSeconds;    // --cpu-limit: RLIMIT_CPU, all threads together (SIGXCPU)
  rlim_t address_space_mib = 4096;  // --memory-limit: RLIMIT_AS (llvmpipe reserves ~1 GiB of address space)
  rlim_t file_size_mib = 64;   // RLIMIT_FSIZE: a lab's raw images are ~8 MiB
  rlim_t open_files = 256;     // RLIMIT_NOFILE: a render worker opens a few (logs, raw images, Mesa's cache)
  // RLIMIT_NPROC is counted per user, over all of the user's processes and
  // threads: a child may start this many more than the user runs when it is
  // forked (llvmpipe starts up to 32 threads). The kernel does not apply it to
  // root, so it is not set then (the process-group kill still ends every helper).
  rlim_t extra_processes = 512;
};

// How a child starts besides its limits.
struct ChildSetup {
  std::filesystem::path working_dir;  // its current directory ("": the grader's)
  std::vector<std::pair<std::string, std::string>> environment;  // variables set (or replaced) in the child
};

// A render worker's exit status when it ran out of memory (std::bad_alloc, or a
// fatal signal or failure with its peak address space at RLIMIT_AS).
constexpr int kOutOfMemoryExit = 86;

struct Outcome {
  enum class Kind { Running, Exited, Signaled, TimedOut, CpuLimit, OutOfMemory };
  Kind kind = Kind::Running;
  int code = 0;           // exit status, or the signal number
  // A worker's (fork_worker) count from the start of its last task: sent (wall), or
  // begun after the last task it reported (CPU).
  double wall_seconds = 0.0;
  double cpu_seconds = 0.0;  // user + system, from wait4
  long max_rss_kib = 0;      // peak resident set, from wait4
  double wall_limit = 0.0;   // the limits it ran under, for describe()
  rlim_t cpu_limit = 0, memory_limit_mib = 0;
  // "exit status 2", "signal 11 (Segmentation fault)", "out of memory (limit 4096 MiB)",
  // "stopped after 30 s of CPU time (the CPU limit)", "stopped after 120 s of wall-clock time (1.2 s of CPU)"
  std::string describe() const;
};

// A forked child that runs numbered tasks one after another (kit-grade's render
// workers: one process and GL context for several labs of a submission, instead of a
// fork, a context and llvmpipe's uncached setup code for each). Each task runs under
// the limits a single child would: its own CPU limit from when it starts, and the wall
// clock restarted when the parent sends it. Only RLIMIT_AS is the process's whole life:
// the parent runs a task again in a fresh child when it ended this one abnormally after
// another task (run/scheduler.cpp, render_again_alone, says when).
//
// The child's side of a task channel.
class TaskChannel {
 public:
  TaskChannel(int socket, rlim_t cpu_seconds) : socket_(socket), cpu_seconds_(cpu_seconds) {}
  // Blocks for the next task; 0 when the parent says stop or is gone. Before it returns
  // a task, the CPU limit is set to the task's own allowance from now.
  int next_task();
  // Flushes stdio, then sends the task's status (kOutOfMemoryExit for a failure with the
  // address space at its limit, as a child's exit status) with the process's CPU time
  // and peak resident set so far.
  void report(int task, int status);
  // stdout and stderr to `log` from now (each task's log of its own).
  static void log_to(const std::filesystem::path& log);

 private:
  int socket_;  // the child's end of a SOCK_SEQPACKET pair: one message a task or report
  rlim_t cpu_seconds_;
};

class Child {
 public:
  // Runs `body` in a forked child; its return value is the exit status.
  static Child fork_function(const std::function<int()>& body, const Limits& limits, const std::filesystem::path& log,
                             const ChildSetup& setup = {});
  // Runs `body` in a forked child that takes up to `max_tasks` tasks (send_task); the
  // body's return value is the exit status. The CPU limit applies to each task and the
  // wall limit from each send_task; the hard CPU limit is max_tasks times the limit.
  static Child fork_worker(const std::function<int(TaskChannel&)>& body, const Limits& limits, int max_tasks,
                           const std::filesystem::path& log, const ChildSetup& setup = {});
  // Runs a program (looked up in PATH) with `args` (args[0] is the program).
  static Child exec_program(const std::vector<std::string>& args, const Limits& limits,
                            const std::filesystem::path& log, const ChildSetup& setup = {});

  Child(Child&& other) noexcept;
  Child& operator=(Child&&) = delete;
  Child(const Child&) = delete;
  Child& operator=(const Child&) = delete;
  ~Child();  // kills and reaps a child still running

  // Non-blocking: reaps the child if it ended, kills its group past the wall limit.
  // True once the outcome is final.
  bool poll();
  // Blocks until the outcome is final.
  const Outcome& wait();
  const Outcome& outcome() const { return outcome_; }
  pid_t pid() const { return pid_; }

  // A worker's parent side. send_task: the next task (0: stop); restarts the wall clock.
  // False when the worker is gone.
  bool send_task(int task);
  // A task the worker has reported, without waiting; nothing when none is there. Its
  // outcome is its status as an exit status would be (Exited, or OutOfMemory), with the
  // task's own wall and CPU time and the worker's peak resident set so far.
  struct TaskResult {
    int task = 0;
    Outcome outcome;
  };
  std::optional<TaskResult> next_report();
  // Seconds since the child started, or since the last send_task.
  double elapsed() const;

 private:
  Child(pid_t pid, const Limits& limits, bool reports_memory);
  void reap(int status, const rusage& usage);
  void kill_all();
  pid_t pid_ = -1;
  bool reports_memory_ = false;  // a forked body: kOutOfMemoryExit means out of memory
  bool killed_for_time_ = false;
  std::chrono::steady_clock::time_point started_;
  Outcome outcome_;
  int channel_ = -1;  // a worker's: the parent's end of its socket pair
  double reported_cpu_ = 0.0;  // a worker's CPU time when it reported its last task
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

// This process's peak address space (VmPeak, what RLIMIT_AS limits) in KiB, 0
// when unknown. Async-signal-safe: a fatal-signal handler calls it.
long peak_address_space_kib();

// Whether a peak address space counts as having reached a limit of `limit_mib`:
// within 1/16 of it (at least 32 MiB), since the allocation that failed is not
// counted in the peak.
bool reached_memory_limit(long peak_kib, rlim_t limit_mib);

// Processes and threads whose real user is `uid`, as RLIMIT_NPROC counts them.
size_t count_user_tasks(uid_t uid);

}  // namespace kit::grade
