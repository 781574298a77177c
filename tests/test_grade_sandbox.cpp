// kit-grade against hostile submissions and hostile shaders (tools/grade/sandbox.*,
// submission.*, grader.*): hard links out of the submission, zips whose listing
// is longer than any bounded read, encrypted and damaged zips, children that
// loop, allocate or open without end, Mesa's shader cache, and batches that
// collide with their own files, with each other, or with a killed run. Each
// test has a witness where one can be had: the attack really works against the
// behaviour replaced (or Mesa's default), and no longer against kit-grade.
//
// Shipped to students: what kit-grade renders is the starter of the first lab
// this kit can grade (lab 1 in the instructor's kit, built on no solution; lab
// N in a student copy for lab N, built on the solutions it holds); the zip
// tests prepare lab 2's files without rendering them.
#include <fcntl.h>
#include <grp.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <signal.h>
#include <sys/file.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <optional>
#include <regex>
#include <string>
#include <system_error>
#include <thread>
#include <vector>

#include "intake/sandbox.h"
#include "intake/submission.h"
#include "kit_test.h"
#include "kit_test_files.h"
#include "render/stages.h"

namespace fs = std::filesystem;
using kit::grade::Child;
using kit::grade::ChildSetup;
using kit::grade::Limits;
using kit::grade::Outcome;
using kit::grade::PreparedSubmission;
using kit::test::read_file;
using kit::test::write_file;
using nlohmann::json;

namespace {

#if defined(__SANITIZE_ADDRESS__)
constexpr bool kAddressSanitizerBuild = true;  // no RLIMIT_AS there (see sandbox.cpp)
#else
constexpr bool kAddressSanitizerBuild = false;
#endif

std::string quoted(const fs::path& p) { return "'" + p.string() + "'"; }

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

json read_json(const fs::path& path) {
  try {
    return json::parse(read_file(path));
  } catch (const std::exception&) {
    return json();
  }
}

std::string kit_grade(const std::string& args) { return kit::test::tool("kit-grade") + " " + args; }

// The lab rendered here: the first this kit can grade from labs/ (lab 1 in the
// instructor's kit, lab N in a student copy for lab N).
const kit::Stage& starter_stage() { return kit::find_stage(kit::gradable_labs().front()); }
std::string lab_key() { return std::to_string(starter_stage().number); }
std::string labs_flag() { return " --labs " + lab_key() + " "; }

// The starters of that lab in `root`/NN-name.
void copy_starters(const fs::path& root) {
  const kit::Stage& stage = starter_stage();
  fs::create_directories(root / stage.folder);
  for (const std::string& file : stage.files)
    fs::copy_file(kit::kit_root() / "labs" / stage.folder / file, root / stage.folder / file,
                  fs::copy_options::overwrite_existing);
}

// The starters with a loop that never ends, at the start of the first function of
// a fragment shader (its main, or a module a fragment shader includes).
void copy_endless_starters(const fs::path& root) {
  copy_starters(root);
  const kit::Stage& stage = starter_stage();
  const std::regex function_start(R"(\n[A-Za-z][A-Za-z0-9_ ]*\([^;{}]*\)\s*\{)");
  for (const std::string& file : stage.files) {
    if (file.find(".vert") != std::string::npos) continue;
    fs::path path = root / stage.folder / file;
    std::string text = read_file(path);
    std::smatch found;
    size_t at = text.find("void main() {");
    if (at != std::string::npos) {
      at += 13;
    } else if (std::regex_search(text, found, function_start)) {
      at = static_cast<size_t>(found.position(0) + found.length(0));
    } else {
      continue;
    }
    // llvmpipe ends a shader's loops after 65535 iterations in all (its guard against
    // hangs), so a loop "that never ends" is only slow there: with a bare addition, 0.6 s
    // of CPU for a frame of lab 1, whose three frames stayed under --cpu-limit 2. Each
    // iteration here costs several times that (two transcendentals); kit_x only grows.
    text.insert(at, "\n    float kit_x = 1.0;\n"
                    "    while (kit_x > 0.0) kit_x += gl_FragCoord.x * (1.0 + abs(sin(kit_x)) + abs(cos(0.5 * kit_x)));"
                    "  // never ends\n"
                    "    if (kit_x < 0.0) discard;\n");
    write_file(path, text);
    return;
  }
  FAIL() << "no fragment shader function in the starters of " << stage.folder;
}

// Python lines (inside a `with ZipFile(...) as z:` block) writing lab 2's files
// (never rendered) as entries under `prefix`.
std::string lab2_entries_python(const std::string& prefix) {
  return "    for n in ('brdf.glsl', 'lighting.frag'):\n"
         "        z.writestr('" + prefix + "' + n, '// ' + n + '\\n')\n";
}

// Runs a Python script (written to `dir`/make.py) in `dir`.
void python(const fs::path& dir, const std::string& script) {
  write_file(dir / "make.py", script);
  std::string output;
  ASSERT_EQ(kit::test::run("cd " + quoted(dir) + " && python3 make.py", &output), 0) << output;
}

// The grader's own preparation of `submission`, in a folder named after the test.
PreparedSubmission prepare(const fs::path& submission, const std::vector<int>& labs) {
  static int count = 0;
  std::string test = ::testing::UnitTest::GetInstance()->current_test_info()->name();
  fs::path temp = kit::test::temp_dir("sandbox-prepare-" + test + "-" + std::to_string(++count));
  return kit::grade::prepare_submission(submission, labs, temp, Limits{});
}

// This process's address space now (VmSize), in MiB.
long address_space_mib() {
  std::string status = read_file("/proc/self/status");
  size_t at = status.find("VmSize:");
  return at == std::string::npos ? 0 : std::atol(status.c_str() + at + 7) / 1024;
}

Outcome run_child(const std::function<int()>& body, const Limits& limits, const fs::path& log,
                  const ChildSetup& setup = {}) {
  Child child = Child::fork_function(body, limits, log, setup);
  return child.wait();
}

}  // namespace

// A hard link in the submission to a file outside it: the link's path lies
// inside, so only the link count (fstat on the opened descriptor) tells.
TEST(GradeSandbox, HardLinkToAFileOutsideIsRefused) {
  fs::path dir = kit::test::temp_dir("sandbox-hard-link");
  // The lab's fragment shader, else a module it includes: text that fails to
  // compile naming the token (Mesa quotes an undeclared name in its log).
  const kit::Stage& stage = starter_stage();
  std::string file = stage.files.front();
  for (const std::string& f : stage.files)
    if (f.find(".frag") != std::string::npos) file = f;
  const bool top_level = file.find(".frag") != std::string::npos;
  const std::string token = "SECRET_OUTSIDE_7f3a9c";
  const std::string secret = top_level ? "#version 330 core\nout vec4 kit_out;\nvoid main() { kit_out = vec4(" + token + "); }\n"
                                       : "const float kit_leak = " + token + ";\n";
  write_file(dir / "outside" / "secret.glsl", secret);
  copy_starters(dir / "linked");
  fs::path link = dir / "linked" / stage.folder / file;
  const std::string shown = "labs/" + stage.folder + "/" + file;
  fs::remove(link);
  fs::create_hard_link(dir / "outside" / "secret.glsl", link);

  // Witness: the link reads the outside file, and that text, graded as a file of
  // the submission, reaches results.json through the compiler log.
  ASSERT_EQ(read_file(link), secret);
  copy_starters(dir / "copied");
  write_file(dir / "copied" / stage.folder / file, secret);
  std::string output;
  ASSERT_EQ(kit::test::run(kit_grade(quoted(dir / "copied") + labs_flag() + "--out " + quoted(dir / "out-copied")), &output), 0)
      << output;
  EXPECT_EQ(read_json(dir / "out-copied" / "summary.json")["labs"][lab_key()]["status"], "compile_error");
  ASSERT_TRUE(contains(read_file(dir / "out-copied" / "results.json"), token)) << "the leak this test guards against";

  PreparedSubmission p = prepare(dir / "linked", {stage.number});
  const kit::grade::LabFiles& lab = p.labs.at(stage.number);
  EXPECT_EQ(lab.status, "invalid_files");
  EXPECT_TRUE(contains(lab.message, shown + ": is a hard link (the file has 2 names")) << lab.message;
  EXPECT_FALSE(fs::exists(p.lab_root / stage.folder / file)) << "nothing of it is copied";

  fs::path out = dir / "out-linked";
  ASSERT_EQ(kit::test::run(kit_grade(quoted(dir / "linked") + labs_flag() + "--out " + quoted(out)), &output), 0) << output;
  json summary = read_json(out / "summary.json");
  EXPECT_EQ(summary["labs"][lab_key()]["status"], "invalid_files") << summary.dump(1);
  EXPECT_TRUE(contains(summary["labs"][lab_key()]["message"].get<std::string>(), shown + ": is a hard link"));
  for (const char* file : {"results.json", "summary.json", "report.html"})
    EXPECT_FALSE(contains(read_file(out / file), token)) << file;
  EXPECT_FALSE(contains(output, token)) << output;
}

// A listing longer than 4 MiB (what the grader used to read of it) with a
// "../" entry near its start: every entry is checked, and the zip refused
// naming it.
TEST(GradeSandbox, ZipListingsAreCheckedWhole) {
  fs::path dir = kit::test::temp_dir("sandbox-zip-listing");
  python(dir, "import zipfile\n"
              "with zipfile.ZipFile('many.zip', 'w') as z:\n" +
                  lab2_entries_python("02-lighting/") +
                  "    z.writestr('../evil', 'x')\n"
                  "    for i in range(12000):\n"
                  "        z.writestr('pad/' + 'n' * 390 + '%06d' % i, '')\n"
                  // Fewer entries than the limit, with long names: the old count said nothing.
                  "with zipfile.ZipFile('long.zip', 'w') as z:\n"
                  "    z.writestr('../long-evil', 'x')\n" +
                  lab2_entries_python("02-lighting/") +
                  "    for i in range(5000):\n"
                  "        z.writestr('pad/' + 'l' * 1000 + '%06d' % i, '')\n"
                  // More entries than kMaxZipEntries, nothing unsafe.
                  "with zipfile.ZipFile('count.zip', 'w') as z:\n" +
                  lab2_entries_python("02-lighting/") +
                  "    for i in range(12000):\n"
                  "        z.writestr('pad/' + '%06d' % i, '')\n");
  // Witness: the listings are longer than 4 MiB and the unsafe entries lie in
  // their first kilobyte, outside their last 4 MiB; long.zip's last 4 MiB also
  // hold fewer entries than kMaxZipEntries, so no count refused it either.
  for (const char* zip : {"many.zip", "long.zip"}) {
    std::string listing;
    ASSERT_EQ(kit::test::run("unzip -Z1 " + quoted(dir / zip), &listing), 0);
    EXPECT_GT(listing.size(), size_t{4} * 1024 * 1024 + 1024) << zip;
    EXPECT_LT(listing.find("evil"), size_t{1024}) << zip;
  }

  PreparedSubmission many = prepare(dir / "many.zip", {2});
  EXPECT_TRUE(contains(many.problem, "many.zip: refused, nothing was extracted")) << many.problem;
  EXPECT_TRUE(contains(many.problem, "'../evil'")) << many.problem;
  EXPECT_EQ(many.labs.at(2).status, "invalid_files");
  EXPECT_FALSE(fs::exists(dir / "evil"));
  PreparedSubmission long_names = prepare(dir / "long.zip", {2});
  EXPECT_TRUE(contains(long_names.problem, "'../long-evil'")) << long_names.problem;
  // With nothing unsafe, the entry count refuses it as a whole, saying so.
  PreparedSubmission count = prepare(dir / "count.zip", {2});
  EXPECT_TRUE(contains(count.problem, "12002 entries, more than the 10000 accepted: refused")) << count.problem;
}

// Encrypted entries: named, never extracted (unzip would ask for a password).
TEST(GradeSandbox, EncryptedZipEntriesAreNamed) {
  fs::path dir = kit::test::temp_dir("sandbox-zip-encrypted");
  for (const std::string& file : kit::find_stage("2").files) write_file(dir / "files" / "02-lighting" / file, "// " + file + "\n");
  std::string output;
  ASSERT_EQ(kit::test::run("cd " + quoted(dir / "files") + " && zip -q -r ../plain.zip . && zip -q -r -e -P secret ../locked.zip .",
                           &output),
            0)
      << output;
  // Witness: the same files without a password are taken.
  EXPECT_TRUE(prepare(dir / "plain.zip", {2}).labs.at(2).ready);
  PreparedSubmission p = prepare(dir / "locked.zip", {2});
  const kit::grade::LabFiles& lab = p.labs.at(2);
  EXPECT_EQ(lab.status, "invalid_files");
  EXPECT_TRUE(contains(lab.message, "labs/02-lighting/brdf.glsl: refused: encrypted entries are not supported: "
                                    "'02-lighting/brdf.glsl' is encrypted"))
      << lab.message;
  EXPECT_FALSE(contains(lab.message, "not in the submission")) << lab.message;
}

// Damaged entries: a bad CRC (stored data with flipped bytes) and deflated data
// that does not inflate are named as such, not "empty" or "missing".
TEST(GradeSandbox, CorruptZipEntriesAreNamed) {
  fs::path dir = kit::test::temp_dir("sandbox-zip-corrupt");
  python(dir, "import random, zipfile\n"
              "random.seed(7)\n"
              "text = '// brdf ' + ''.join(random.choice('abcdefghijklmnopqrstuvwxyz ') for _ in range(3000)) + '\\n'\n"
              "for name, method in (('stored', zipfile.ZIP_STORED), ('deflated', zipfile.ZIP_DEFLATED)):\n"
              "    with zipfile.ZipFile(name + '.zip', 'w', compression=method) as z:\n"
              "        z.writestr('02-lighting/brdf.glsl', text)\n"
              "        z.writestr('02-lighting/lighting.frag', '// lighting\\n')\n"
              "    data = bytearray(open(name + '.zip', 'rb').read())\n"
              "    open(name + '-intact.zip', 'wb').write(data)\n"
              "    at = data.index(b'02-lighting/brdf.glsl') + len('02-lighting/brdf.glsl') + 40\n"
              "    for k in range(40): data[at + k] ^= 0x5a\n"
              "    open(name + '.zip', 'wb').write(data)\n");
  for (const char* name : {"stored", "deflated"}) {
    SCOPED_TRACE(name);
    // Witness: the zips were whole before their bytes were flipped.
    EXPECT_TRUE(prepare(dir / (std::string(name) + "-intact.zip"), {2}).labs.at(2).ready);
    PreparedSubmission p = prepare(dir / (std::string(name) + ".zip"), {2});
    const kit::grade::LabFiles& lab = p.labs.at(2);
    EXPECT_EQ(lab.status, "invalid_files");
    EXPECT_TRUE(contains(lab.message, "labs/02-lighting/brdf.glsl: refused: the archive's entry '02-lighting/brdf.glsl' "
                                      "is corrupt"))
        << lab.message;
    if (std::string(name) == "stored") {
      EXPECT_TRUE(contains(lab.message, "CRC")) << lab.message;
    }
    EXPECT_FALSE(contains(lab.message, "empty")) << lab.message;
    EXPECT_FALSE(contains(lab.message, "lighting.frag")) << "the intact entry is taken: " << lab.message;
  }
}

// The time limit is CPU time: a child that loops is stopped by RLIMIT_CPU long
// before the wall clock, and one that only waits (as a renderer on a busy
// machine does) is not stopped at all; the wall clock stays a backstop.
TEST(GradeSandbox, CpuTimeIsTheTimeLimit) {
  fs::path dir = kit::test::temp_dir("sandbox-cpu");
  Limits limits;
  limits.cpu_seconds = 1;
  limits.wall_seconds = 60;
  Outcome busy = run_child([]() -> int {
    volatile unsigned long spin = 0;
    for (;;) spin = spin + 1;
  }, limits, dir / "busy.log");
  EXPECT_EQ(busy.kind, Outcome::Kind::CpuLimit) << busy.describe();
  EXPECT_GE(busy.cpu_seconds, 0.5);  // wait4's count may read under the kernel's on a loaded machine
  EXPECT_LT(busy.wall_seconds, 60.0);
  EXPECT_EQ(busy.describe(), "stopped after 1 s of CPU time (the CPU limit)");
  // Witness: more wall-clock time than the CPU limit, little CPU: not stopped.
  Outcome waiting = run_child([] {
    std::this_thread::sleep_for(std::chrono::milliseconds(2500));
    return 0;
  }, limits, dir / "waiting.log");
  EXPECT_EQ(waiting.kind, Outcome::Kind::Exited) << waiting.describe();
  EXPECT_GE(waiting.wall_seconds, 2.5);
  limits.wall_seconds = 1;
  Outcome stuck = run_child([] {
    std::this_thread::sleep_for(std::chrono::seconds(30));
    return 0;
  }, limits, dir / "stuck.log");
  EXPECT_EQ(stuck.kind, Outcome::Kind::TimedOut) << stuck.describe();
  EXPECT_TRUE(contains(stuck.describe(), "stopped after 1 s of wall-clock time")) << stuck.describe();
}

// A worker (kit-grade's render worker: several labs in one process) runs each task under
// the limits a child of its own would have: the CPU limit and the wall clock count from
// the task's start. Three tasks of 0.6 s of CPU each pass a 1 s CPU limit, and three of
// 1.2 s of waiting each a 2 s wall limit, that their sums would break (each limit in a
// worker of its own, so a loaded machine stretching the spinning cannot reach the wall
// limit); the witness in each is a fourth task that breaks the limit on its own, and is
// stopped by it, with its report missing.
TEST(GradeSandbox, WorkerTasksHaveLimitsOfTheirOwn) {
  fs::path dir = kit::test::temp_dir("sandbox-worker");
  auto cpu_now = [] {
    rusage usage{};
    getrusage(RUSAGE_SELF, &usage);
    return static_cast<double>(usage.ru_utime.tv_sec + usage.ru_stime.tv_sec) +
           1e-6 * static_cast<double>(usage.ru_utime.tv_usec + usage.ru_stime.tv_usec);
  };
  // Each task: `work(task)`, its log line, then its report (status 10 x task).
  auto run_tasks = [&](const std::string& name, const Limits& limits, const std::function<void(int)>& work,
                       double min_task_cpu, Outcome::Kind stopped_as) {
    Child worker = Child::fork_worker(
        [&](kit::grade::TaskChannel& channel) {
          while (int task = channel.next_task()) {
            kit::grade::TaskChannel::log_to(dir / (name + std::to_string(task) + ".log"));
            std::printf("task %d\n", task);
            work(task);
            channel.report(task, 10 * task);
          }
          return 0;
        },
        limits, 4, dir / (name + ".log"));
    Outcome sum;
    for (int task = 1; task <= 4; ++task) {
      SCOPED_TRACE(name + " task " + std::to_string(task));
      EXPECT_TRUE(worker.send_task(task));
      std::optional<Child::TaskResult> report;
      while (!report && !worker.poll()) {
        kit::grade::poll_pause();
        report = worker.next_report();
      }
      if (task < 4) {
        if (!report) ADD_FAILURE() << worker.outcome().describe();
        if (!report) return sum;
        EXPECT_EQ(report->task, task);
        EXPECT_EQ(report->outcome.kind, Outcome::Kind::Exited);
        EXPECT_EQ(report->outcome.code, 10 * task);
        EXPECT_GE(report->outcome.cpu_seconds, min_task_cpu);
        EXPECT_GT(report->outcome.max_rss_kib, 0);
        EXPECT_EQ(read_file(dir / (name + std::to_string(task) + ".log")), "task " + std::to_string(task) + "\n");
        sum.cpu_seconds += report->outcome.cpu_seconds;
        sum.wall_seconds += report->outcome.wall_seconds;
      } else {
        EXPECT_FALSE(report);
        EXPECT_EQ(worker.outcome().kind, stopped_as) << worker.outcome().describe();
      }
    }
    return sum;
  };
  Limits cpu_limits;
  cpu_limits.cpu_seconds = 1;
  cpu_limits.wall_seconds = 60;
  const Outcome spun = run_tasks("spin", cpu_limits, [&](int task) {
    const double start = cpu_now();
    volatile unsigned long spin = 0;
    while (task == 4 || cpu_now() - start < 0.6) spin = spin + 1;
  }, 0.5, Outcome::Kind::CpuLimit);  // 0.5: its own 0.6 s, as wait4 counts it
  EXPECT_GE(spun.cpu_seconds, 1.5);  // more than the limit together
  Limits wall_limits;
  wall_limits.cpu_seconds = 30;
  wall_limits.wall_seconds = 2;
  const Outcome waited = run_tasks("wait", wall_limits, [](int task) {
    std::this_thread::sleep_for(std::chrono::milliseconds(task == 4 ? 30000 : 1200));
  }, 0.0, Outcome::Kind::TimedOut);
  EXPECT_GE(waited.wall_seconds, 3.6);  // more than the wall limit together
  // A worker told to stop ends with its body's status; a task sent to one that is gone fails.
  Child idle = Child::fork_worker([](kit::grade::TaskChannel& channel) { return channel.next_task() == 0 ? 7 : 1; },
                                  cpu_limits, 1, dir / "idle.log");
  ASSERT_TRUE(idle.send_task(0));
  EXPECT_EQ(idle.wait().kind, Outcome::Kind::Exited);
  EXPECT_EQ(idle.outcome().code, 7);
  EXPECT_FALSE(idle.send_task(1));
}

// Running out of address space is named, whether the child sees std::bad_alloc
// or (as Mesa and LLVM do) crashes after an allocation failed.
TEST(GradeSandbox, OutOfMemoryIsNamed) {
  if (kAddressSanitizerBuild) GTEST_SKIP() << "no RLIMIT_AS in a sanitizer build";
  fs::path dir = kit::test::temp_dir("sandbox-memory");
  Limits limits;
  limits.address_space_mib = static_cast<rlim_t>(address_space_mib() + 256);
  const std::string named = "out of memory (limit " + std::to_string(limits.address_space_mib) + " MiB)";
  Outcome thrown = run_child([] {
    std::vector<char> huge(size_t{16} << 30);
    return static_cast<int>(huge[1]);
  }, limits, dir / "bad_alloc.log");
  EXPECT_EQ(thrown.kind, Outcome::Kind::OutOfMemory) << thrown.describe();
  EXPECT_EQ(thrown.describe(), named);
  Outcome crashed = run_child([] {
    std::vector<void*> blocks;
    while (void* block = std::malloc(size_t{16} << 20)) blocks.push_back(block);
    raise(SIGSEGV);  // what a C library does with the null pointer it got
    return 0;
  }, limits, dir / "segv.log");
  EXPECT_EQ(crashed.kind, Outcome::Kind::OutOfMemory) << crashed.describe();
  EXPECT_EQ(crashed.describe(), named);
  EXPECT_TRUE(contains(read_file(dir / "segv.log"), "out of memory: signal 11")) << read_file(dir / "segv.log");
  // Witness: the same crash far from the limit stays a crash.
  Outcome plain = run_child([] {
    raise(SIGSEGV);
    return 0;
  }, limits, dir / "plain.log");
  EXPECT_EQ(plain.kind, Outcome::Kind::Signaled) << plain.describe();
  EXPECT_EQ(plain.code, SIGSEGV);
}

// A child works in the folder it is given, with the environment it is given,
// no controlling terminal, and few open files.
TEST(GradeSandbox, ChildrenHaveTheirFolderAndFewOpenFiles) {
  fs::path dir = kit::test::temp_dir("sandbox-files");
  Limits limits;
  limits.open_files = 32;
  ChildSetup setup;
  setup.working_dir = dir / "work";
  setup.environment = {{"MESA_SHADER_CACHE_DIR", (dir / "work" / "cache").string()}};
  fs::create_directories(setup.working_dir);
  Outcome o = run_child([&] {
    const char* cache = std::getenv("MESA_SHADER_CACHE_DIR");
    if (!cache || cache != (dir / "work" / "cache").string()) return 10;
    if (open("/dev/tty", O_RDONLY) >= 0) return 11;
    std::vector<int> fds;
    for (int fd = 0; fds.size() < 1000 && (fd = open("/dev/null", O_RDONLY)) >= 0;) fds.push_back(fd);
    for (int fd : fds) close(fd);
    write_file("opened.txt", std::to_string(fds.size()));  // relative: lands in the working directory
    return 0;
  }, limits, dir / "child.log", setup);
  ASSERT_EQ(o.kind, Outcome::Kind::Exited) << o.describe();
  ASSERT_EQ(o.code, 0) << read_file(dir / "child.log");
  int opened = std::stoi(read_file(dir / "work" / "opened.txt"));
  EXPECT_LT(opened, 32);
  // Witness: this process, without the limit, opens far more.
  std::vector<int> fds;
  for (int i = 0; i < 100; ++i) fds.push_back(open("/dev/null", O_RDONLY));
  EXPECT_GE(*std::min_element(fds.begin(), fds.end()), 0);
  for (int fd : fds) close(fd);
}

// RLIMIT_NPROC counts the user's processes and threads: a child may start only
// a few more than its user has. The kernel exempts root, so as root the check
// runs as nobody in a process of its own.
TEST(GradeSandbox, ProcessCountIsLimited) {
  // Threads started by a child allowed `extra` more tasks; -1 when the child failed.
  auto threads_started = [](rlim_t extra) -> int {
    Limits limits;
    limits.extra_processes = extra;
    Outcome o = run_child([] {
      std::vector<std::thread> threads;
      int started = 0;
      for (int i = 0; i < 64; ++i) {
        try {
          threads.emplace_back([] { std::this_thread::sleep_for(std::chrono::milliseconds(300)); });
          ++started;
        } catch (const std::system_error&) {
        }
      }
      for (std::thread& t : threads) t.join();
      return started;
    }, limits, "/dev/null");
    return o.kind == Outcome::Kind::Exited ? o.code : -1;
  };
  if (getuid() != 0) {
    EXPECT_LT(threads_started(8), 8);
    EXPECT_EQ(threads_started(0), 64) << "witness: without the limit every thread starts";
    return;
  }
  pid_t helper = fork();
  ASSERT_GE(helper, 0);
  if (helper == 0) {
    if (setgroups(0, nullptr) != 0 || setgid(65534) != 0 || setuid(65534) != 0) _exit(100);
    int limited = threads_started(8), unlimited = threads_started(0);
    _exit(limited >= 0 && limited < 8 && unlimited == 64 ? 0 : 1 + (limited < 0 ? 0 : limited % 50));
  }
  int status = 0;
  waitpid(helper, &status, 0);
  ASSERT_TRUE(WIFEXITED(status));
  if (WEXITSTATUS(status) == 100) GTEST_SKIP() << "cannot become nobody to check RLIMIT_NPROC as root";
  EXPECT_EQ(WEXITSTATUS(status), 0) << "as nobody: threads started under the limit, or a failed child";
}

// kit-grade end to end: the lab of a renderer that runs out of memory says so.
TEST(GradeSandbox, KitGradeReportsOutOfMemory) {
  if (kAddressSanitizerBuild) GTEST_SKIP() << "no RLIMIT_AS in a sanitizer build";
  fs::path dir = kit::test::temp_dir("sandbox-kit-grade-memory");
  copy_starters(dir / "alice");
  std::string output;
  ASSERT_EQ(kit::test::run(kit_grade(quoted(dir / "alice") + labs_flag() + "--memory-limit 256 --out " + quoted(dir / "out")),
                           &output),
            0)
      << output;
  json lab = read_json(dir / "out" / "summary.json")["labs"][lab_key()];
  EXPECT_EQ(lab["status"], "crash") << lab.dump(1);
  EXPECT_EQ(lab["message"].get<std::string>().rfind("out of memory (limit 256 MiB)", 0), 0u) << lab.dump(1);
  EXPECT_TRUE(contains(output, "out of memory (limit 256 MiB)")) << output;
  EXPECT_FALSE(contains(lab["message"].get<std::string>(), "signal 11 (Segmentation fault))")) << lab.dump(1);
  // Witness: under the default limit the same lab renders.
  ASSERT_EQ(kit::test::run(kit_grade(quoted(dir / "alice") + labs_flag() + "--out " + quoted(dir / "out-default")), &output), 0)
      << output;
  EXPECT_EQ(read_json(dir / "out-default" / "summary.json")["labs"][lab_key()]["status"], "graded");
}

// Grading renders with Mesa's software rasteriser unless --gpu asks for the platform's
// first device, and summary.json and the report say which (common/gl/context.h).
TEST(GradeSandbox, KitGradeNamesTheDeviceItRenderedWith) {
  fs::path dir = kit::test::temp_dir("sandbox-kit-grade-device");
  copy_starters(dir / "alice");
  std::string output;
  for (const char* backend : {"egl", kit::default_headless_backend_name()}) {
    const fs::path out = dir / (std::string("out-") + backend);
    ASSERT_EQ(kit::test::run(kit_grade(quoted(dir / "alice") + labs_flag() + "--backend " + backend + " --out " +
                                       quoted(out)), &output), 0) << output;
    json summary = read_json(out / "summary.json");
    EXPECT_EQ(summary["device"], "software") << backend;
    const std::string renderer = summary.value("renderer", "");
    EXPECT_TRUE(contains(renderer, "llvmpipe") || contains(renderer, "softpipe")) << renderer;
    EXPECT_FALSE(contains(read_file(out / "report.html"), "Graded with --gpu")) << backend;
  }
  ASSERT_EQ(kit::test::run(kit_grade(quoted(dir / "alice") + labs_flag() + "--backend egl --gpu --out " +
                                     quoted(dir / "out-gpu")), &output), 0) << output;
  EXPECT_EQ(read_json(dir / "out-gpu" / "summary.json")["device"], "gpu");
  EXPECT_TRUE(contains(read_file(dir / "out-gpu" / "report.html"), "Graded with --gpu"));
  EXPECT_TRUE(contains(read_file(dir / "out-gpu" / "results.json"), "Graded with --gpu"));
}

// kit-grade end to end: a shader that never ends is stopped by the CPU limit,
// long before the wall-clock backstop.
TEST(GradeSandbox, KitGradeStopsAnEndlessLoopByCpuTime) {
  fs::path dir = kit::test::temp_dir("sandbox-kit-grade-cpu");
  copy_endless_starters(dir / "alice");
  std::string output;
  auto t0 = std::chrono::steady_clock::now();
  ASSERT_EQ(kit::test::run(kit_grade(quoted(dir / "alice") + labs_flag() + "--cpu-limit 2 --timeout 300 --out " +
                                     quoted(dir / "out")),
                           &output),
            0)
      << output;
  double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  json lab = read_json(dir / "out" / "summary.json")["labs"][lab_key()];
  EXPECT_EQ(lab["status"], "timeout") << lab.dump(1);
  EXPECT_TRUE(contains(lab["message"].get<std::string>(), "more than 2 s of CPU time (--cpu-limit)")) << lab.dump(1);
  EXPECT_LT(seconds, 300.0);
}

// Mesa writes its shader cache under $XDG_CACHE_HOME (else ~/.cache) by default;
// kit-grade's children write theirs in the submission's temporary folder.
TEST(GradeSandbox, KitGradeKeepsMesasShaderCachePrivate) {
  fs::path dir = kit::test::temp_dir("sandbox-shader-cache");
  const std::string env = "env -u MESA_SHADER_CACHE_DIR -u MESA_SHADER_CACHE_DISABLE -u MESA_GLSL_CACHE_DISABLE ";
  std::string output;
  // Witness: kit-render (no sandbox) fills the user's cache.
  ASSERT_EQ(kit::test::run(env + "XDG_CACHE_HOME=" + quoted(dir / "render-cache") + " " + kit::test::tool("kit-render") +
                               " --shaders " + quoted(kit::kit_root() / "labs" / starter_stage().folder) + " --out " +
                               quoted(dir / "render.png"),
                           &output),
            0)
      << output;
  ASSERT_TRUE(fs::exists(dir / "render-cache" / "mesa_shader_cache")) << "Mesa's default this test relies on";
  fs::create_directories(dir / "tmp");
  copy_starters(dir / "alice");
  const std::string grade = env + "TMPDIR=" + quoted(dir / "tmp") + " " +
                            kit_grade(quoted(dir / "alice") + labs_flag() + "--keep-temp --out " + quoted(dir / "out"));
  ASSERT_EQ(kit::test::run("XDG_CACHE_HOME=" + quoted(dir / "grade-cache") + " " + grade, &output), 0) << output;
  EXPECT_EQ(read_json(dir / "out" / "summary.json")["labs"][lab_key()]["status"], "graded");
  // Nothing a shader compiled to reaches the user's cache: only the grader's own decoded
  // references (kit-grade/references/, made from the kit's reference files) are kept there.
  if (fs::exists(dir / "grade-cache")) {
    for (const auto& entry : fs::recursive_directory_iterator(dir / "grade-cache")) {
      if (entry.is_regular_file()) {
        EXPECT_EQ(entry.path().parent_path(), dir / "grade-cache" / "kit-grade" / "references") << entry.path();
      }
    }
  }
  // The cache was used, privately: in the kept temporary folder of the submission.
  auto private_cache_files = [&] {
    std::vector<std::string> files;
    for (const auto& entry : fs::recursive_directory_iterator(dir / "tmp"))
      if (entry.is_regular_file() && contains(entry.path().string(), "/mesa-shader-cache/"))
        files.push_back(entry.path().filename().string());
    return files;
  };
  EXPECT_FALSE(private_cache_files().empty());
  // Mesa's single-file cache (a few files to copy per submission), not its default of
  // a file per program (the witness above: kit-render's cache is that folder).
  const std::vector<std::string> files = private_cache_files();
  EXPECT_NE(std::find(files.begin(), files.end(), "foz_cache.foz"), files.end());
  for (const auto& entry : fs::recursive_directory_iterator(dir / "tmp"))
    EXPECT_FALSE(contains(entry.path().string(), "/mesa-shader-cache/mesa_shader_cache/")) << entry.path();

  // With a seed (what --check-references writes from the solutions), the private
  // cache starts as a copy of it, and grading writes nothing into the seed.
  fs::remove_all(dir / "tmp");
  fs::create_directories(dir / "tmp");
  fs::path seed = dir / "seeded-cache" / "kit-grade" / "mesa-shader-cache";
  write_file(seed / "seed-marker", "from the kit's own renders\n");
  ASSERT_EQ(kit::test::run("XDG_CACHE_HOME=" + quoted(dir / "seeded-cache") + " " + grade, &output), 0) << output;
  std::vector<std::string> copied = private_cache_files();
  EXPECT_NE(std::find(copied.begin(), copied.end(), "seed-marker"), copied.end());
  EXPECT_GT(copied.size(), 1u);
  size_t seed_files = 0;
  for (const auto& entry : fs::recursive_directory_iterator(seed))
    if (entry.is_regular_file()) ++seed_files;
  EXPECT_EQ(seed_files, 1u) << "a student's programs never reach the seed";
}

// A student folder named gradebook.csv grades fine and the gradebook stays a
// file. An output folder an older kit-grade left with such a result folder in
// the gradebook's place (every later batch failed: "Is a directory") recovers.
TEST(GradeSandbox, BatchSubmissionNamedLikeTheGradebook) {
  fs::path dir = kit::test::temp_dir("sandbox-batch-names");
  fs::path in = dir / "in", out = dir / "out";
  copy_starters(in / "gradebook.csv");
  copy_starters(in / "alice");
  const std::string command = kit_grade("--batch " + quoted(in) + " --out " + quoted(out) + labs_flag());
  std::string output;
  ASSERT_EQ(kit::test::run(command, &output), 0) << output;
  EXPECT_TRUE(contains(output, "gradebook.csv -> gradebook.csv.submission/")) << output;
  ASSERT_TRUE(fs::is_regular_file(out / "gradebook.csv")) << output;
  std::string csv = read_file(out / "gradebook.csv");
  EXPECT_EQ(csv.rfind("submission,lab" + lab_key() + ",total,max_total,problems\n", 0), 0u) << csv;
  EXPECT_TRUE(contains(csv, "\nalice,")) << csv;
  EXPECT_TRUE(contains(csv, "\ngradebook.csv,")) << csv;
  EXPECT_EQ(read_json(out / "gradebook.csv.submission" / "summary.json")["labs"][lab_key()]["status"], "graded");

  // Witness: the layout an older kit-grade left (the submission's result folder
  // in the gradebook's place). The next run moves it and writes the gradebook.
  fs::remove(out / "gradebook.csv");
  fs::rename(out / "gradebook.csv.submission", out / "gradebook.csv");
  ASSERT_EQ(kit::test::run(command, &output), 0) << output;
  EXPECT_TRUE(contains(output, "moved " + (out / "gradebook.csv").string())) << output;
  EXPECT_TRUE(contains(output, "0 to grade, 2 already graded")) << output;
  ASSERT_TRUE(fs::is_regular_file(out / "gradebook.csv"));
  EXPECT_TRUE(contains(read_file(out / "gradebook.csv"), "\ngradebook.csv,"));
}

// One batch at a time per output folder: a second is refused naming the
// process that holds the lock (here this test holds it, as a running batch does).
TEST(GradeSandbox, SecondBatchOnOneOutputFolderIsRefused) {
  fs::path dir = kit::test::temp_dir("sandbox-batch-lock");
  fs::path in = dir / "in", out = dir / "out";
  copy_starters(in / "alice");
  fs::create_directories(out);
  int fd = open((out / ".kit-grade.lock").c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  ASSERT_GE(fd, 0);
  ASSERT_EQ(flock(fd, LOCK_EX | LOCK_NB), 0);
  std::string pid = std::to_string(getpid());
  ASSERT_EQ(write(fd, (pid + "\n").data(), pid.size() + 1), static_cast<ssize_t>(pid.size() + 1));
  const std::string command = kit_grade("--batch " + quoted(in) + " --out " + quoted(out) + labs_flag());
  std::string output;
  EXPECT_EQ(kit::test::run(command, &output), 2) << output;
  EXPECT_TRUE(contains(output, "another kit-grade batch (pid " + pid + ") is grading into this folder")) << output;
  EXPECT_FALSE(fs::exists(out / "gradebook.csv"));
  EXPECT_FALSE(fs::exists(out / "alice"));
  close(fd);
  // Once the lock is free, the same command grades.
  ASSERT_EQ(kit::test::run(command, &output), 0) << output;
  EXPECT_TRUE(fs::exists(out / "alice" / "results.json"));
}

// kill -9 leaves a run's temporary folder behind; the next run removes it (and
// only folders whose process is gone), saying so.
TEST(GradeSandbox, TemporaryFoldersOfKilledRunsAreRemoved) {
  fs::path dir = kit::test::temp_dir("sandbox-killed-run");
  fs::path tmp = dir / "tmp";
  fs::create_directories(tmp);
  copy_endless_starters(dir / "endless");
  std::string lab = lab_key(), grader = kit::test::tool("kit-grade"), submission = (dir / "endless").string(), out = (dir / "out").string();
  pid_t run = fork();
  ASSERT_GE(run, 0);
  if (run == 0) {
    setenv("TMPDIR", tmp.c_str(), 1);
    int null = open("/dev/null", O_WRONLY);
    dup2(null, STDOUT_FILENO);
    dup2(null, STDERR_FILENO);
    execl(grader.c_str(), grader.c_str(), submission.c_str(), "--labs", lab.c_str(), "--cpu-limit", "120", "--timeout", "120",
          "--out", out.c_str(), static_cast<char*>(nullptr));
    _exit(127);
  }
  // Wait until it renders (its submission's folder exists), then kill -9 it.
  const std::string prefix = "kit-grade-" + std::to_string(run) + "-";
  fs::path left;
  for (int i = 0; i < 6000 && left.empty(); ++i) {
    for (const auto& entry : fs::directory_iterator(tmp)) {
      if (entry.path().filename().string().rfind(prefix, 0) != 0) continue;
      for (const auto& inner : fs::directory_iterator(entry.path()))
        if (fs::exists(inner.path() / ("lab" + lab))) left = entry.path();
    }
    if (left.empty()) std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  kill(run, SIGKILL);
  int status = 0;
  waitpid(run, &status, 0);
  ASSERT_FALSE(left.empty()) << "the run never started rendering";
  // Witness: the killed run's folder is still there.
  ASSERT_TRUE(fs::exists(left));
  fs::path alive = tmp / ("kit-grade-" + std::to_string(getpid()) + "-living");
  fs::create_directories(alive);

  copy_starters(dir / "alice");
  std::string output;
  ASSERT_EQ(kit::test::run("TMPDIR=" + quoted(tmp) + " " + kit_grade(quoted(dir / "alice") + labs_flag() + "--out " + quoted(dir / "out2")),
                           &output),
            0)
      << output;
  EXPECT_TRUE(contains(output, "kit-grade: removed 1 temporary folder left by kit-grade runs that ended without removing "
                               "them: " + left.string() + " (pid " + std::to_string(run) + ")"))
      << output;
  EXPECT_FALSE(fs::exists(left));
  EXPECT_TRUE(fs::exists(alive)) << "a folder whose process lives is kept";
}
