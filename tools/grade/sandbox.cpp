#include "sandbox.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <thread>
#include <utility>

#include "error.h"

namespace fs = std::filesystem;

namespace kit::grade {

namespace {

// AddressSanitizer reserves terabytes of shadow address space up front, so an
// address-space limit would stop every child of a sanitizer build (the asan
// preset); there the CPU limit and the wall-clock timeout still apply.
#if defined(__SANITIZE_ADDRESS__)
constexpr bool kAddressSanitizerBuild = true;
#else
constexpr bool kAddressSanitizerBuild = false;
#endif


constexpr rlim_t kMiB = 1024 * 1024;
// RLIMIT_CPU's soft limit sends SIGXCPU; the hard limit this much later SIGKILLs.
constexpr rlim_t kCpuHardGraceSeconds = 5;
// Between two polls of running children.
constexpr auto kPollPause = std::chrono::milliseconds(2);

// In the child, before the body runs or the program is exec'd: its own process
// group, the limits, the log as stdout and stderr, no stdin. Only
// async-signal-safe calls, as after fork() in any process.
void enter_child(const Limits& limits, const char* log_path) {
  setpgid(0, 0);
  prctl(PR_SET_PDEATHSIG, SIGKILL);  // its own group gets no terminal signals: die with the grader
  sigset_t unblock;
  sigemptyset(&unblock);
  sigaddset(&unblock, SIGINT);
  sigaddset(&unblock, SIGTERM);
  sigprocmask(SIG_UNBLOCK, &unblock, nullptr);
  rlimit cpu{limits.cpu_seconds, limits.cpu_seconds + kCpuHardGraceSeconds};
  setrlimit(RLIMIT_CPU, &cpu);
  if (!kAddressSanitizerBuild) {
    rlimit as{limits.address_space_mib * kMiB, limits.address_space_mib * kMiB};
    setrlimit(RLIMIT_AS, &as);
  }
  rlimit fsize{limits.file_size_mib * kMiB, limits.file_size_mib * kMiB};
  setrlimit(RLIMIT_FSIZE, &fsize);
  rlimit no_core{0, 0};  // a crashing student shader must not leave core files behind
  setrlimit(RLIMIT_CORE, &no_core);
  int log = open(log_path, O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (log >= 0) {
    dup2(log, STDOUT_FILENO);
    dup2(log, STDERR_FILENO);
    close(log);
  }
  int null = open("/dev/null", O_RDONLY | O_CLOEXEC);
  if (null >= 0) {
    dup2(null, STDIN_FILENO);
    close(null);
  }
}

pid_t fork_or_throw() {
  std::fflush(stdout);  // buffered output would otherwise be written twice
  std::fflush(stderr);
  pid_t pid = fork();
  if (pid < 0) throw Error(std::string("kit-grade: fork failed: ") + std::strerror(errno));
  return pid;
}

}  // namespace

std::string Outcome::describe() const {
  char buf[160];
  switch (kind) {
    case Kind::Running: return "still running";
    case Kind::Exited: std::snprintf(buf, sizeof buf, "exit status %d", code); return buf;
    case Kind::Signaled:
      std::snprintf(buf, sizeof buf, "signal %d (%s)", code, strsignal(code));
      return buf;
    case Kind::TimedOut: std::snprintf(buf, sizeof buf, "killed after %.1f s", wall_seconds); return buf;
  }
  return "?";
}

Child::Child(pid_t pid, double wall_seconds)
    : pid_(pid), wall_limit_(wall_seconds), started_(std::chrono::steady_clock::now()) {
  setpgid(pid, pid);  // also in the child: whichever runs first, the group exists before any kill
}

Child::Child(Child&& other) noexcept
    : pid_(std::exchange(other.pid_, -1)),
      wall_limit_(other.wall_limit_),
      killed_for_time_(other.killed_for_time_),
      started_(other.started_),
      outcome_(other.outcome_) {}

Child::~Child() {
  if (pid_ > 0 && outcome_.kind == Outcome::Kind::Running) {
    kill(-pid_, SIGKILL);
    int status = 0;
    while (waitpid(pid_, &status, 0) < 0 && errno == EINTR) {
    }
  }
}

Child Child::fork_function(const std::function<int()>& body, const Limits& limits, const fs::path& log) {
  std::string log_path = log.string();
  pid_t pid = fork_or_throw();
  if (pid == 0) {
    enter_child(limits, log_path.c_str());
    int code = 1;
    try {
      code = body();
    } catch (const std::exception& e) {
      std::fprintf(stderr, "kit-grade: child: %s\n", e.what());
    } catch (...) {
      std::fprintf(stderr, "kit-grade: child: unknown exception\n");
    }
    std::fflush(nullptr);
    _exit(code);  // no atexit handlers or static destructors of the parent's state
  }
  return Child(pid, limits.wall_seconds);
}

Child Child::exec_program(const std::vector<std::string>& args, const Limits& limits, const fs::path& log) {
  std::string log_path = log.string();
  std::vector<char*> argv;
  for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  pid_t pid = fork_or_throw();
  if (pid == 0) {
    enter_child(limits, log_path.c_str());
    execvp(argv[0], argv.data());
    const char msg[] = "kit-grade: could not run the program\n";
    ssize_t ignored = write(STDERR_FILENO, msg, sizeof msg - 1);
    (void)ignored;
    _exit(127);
  }
  return Child(pid, limits.wall_seconds);
}

void Child::reap(int status, const rusage& usage) {
  outcome_.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started_).count();
  outcome_.cpu_seconds = static_cast<double>(usage.ru_utime.tv_sec + usage.ru_stime.tv_sec) +
                         1e-6 * static_cast<double>(usage.ru_utime.tv_usec + usage.ru_stime.tv_usec);
  outcome_.max_rss_kib = usage.ru_maxrss;
  if (killed_for_time_) {
    outcome_.kind = Outcome::Kind::TimedOut;
  } else if (WIFSIGNALED(status)) {
    outcome_.kind = Outcome::Kind::Signaled;
    outcome_.code = WTERMSIG(status);
  } else {
    outcome_.kind = Outcome::Kind::Exited;
    outcome_.code = WEXITSTATUS(status);
  }
  kill(-pid_, SIGKILL);  // anything the child left behind in its group
}

bool Child::poll() {
  if (outcome_.kind != Outcome::Kind::Running) return true;
  int status = 0;
  rusage usage{};
  pid_t r = wait4(pid_, &status, WNOHANG, &usage);
  if (r == pid_) {
    reap(status, usage);
    return true;
  }
  if (r < 0 && errno != EINTR) {  // not our child any more: nothing to wait for
    outcome_.kind = Outcome::Kind::Exited;
    outcome_.code = -1;
    return true;
  }
  double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - started_).count();
  if (elapsed > wall_limit_ && !killed_for_time_) {
    killed_for_time_ = true;
    kill(-pid_, SIGKILL);
  }
  return false;
}

const Outcome& Child::wait() {
  while (!poll()) poll_pause();
  return outcome_;
}

InterruptGuard::InterruptGuard() {
  sigemptyset(&blocked_);
  sigaddset(&blocked_, SIGINT);
  sigaddset(&blocked_, SIGTERM);
  sigprocmask(SIG_BLOCK, &blocked_, &previous_);
}

InterruptGuard::~InterruptGuard() { sigprocmask(SIG_SETMASK, &previous_, nullptr); }

int InterruptGuard::pending() const {
  timespec zero{0, 0};
  int sig = sigtimedwait(&blocked_, nullptr, &zero);
  return sig > 0 ? sig : 0;
}

void poll_pause() { std::this_thread::sleep_for(kPollPause); }

std::string read_tail(const fs::path& path, size_t max_bytes) {
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) return "";
  std::streamoff size = in.tellg();
  std::streamoff start = size > static_cast<std::streamoff>(max_bytes) ? size - static_cast<std::streamoff>(max_bytes) : 0;
  in.seekg(start);
  std::string text(static_cast<size_t>(size - start), '\0');
  in.read(text.data(), static_cast<std::streamsize>(text.size()));
  return text;
}

}  // namespace kit::grade
