#include "batch/batch.h"

#include <nlohmann/json.hpp>
#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <set>

#include "base/error.h"
#include "batch/class_summary.h"
#include "files/files.h"
#include "gl/pass_clock.h"
#include "intake/submission.h"
#include "report/report.h"
#include "run/grading_run.h"
#include "run/scheduler.h"

namespace fs = std::filesystem;

namespace kit::grade {

namespace {

// A batch's lock in its output folder (hidden: no submission's name can be it).
constexpr const char* kBatchLockFile = ".kit-grade.lock";
// What a batch writes at the top of its output folder, and what a result folder
// holds: a submission named like one of them (in any case) gets its result
// folder under its name plus kReservedSuffix.
const char* const kBatchOwnNames[] = {"gradebook.csv", "class-summary.csv", "class-summary.html", "results.json",
                                       "summary.json", "report.html", "img"};
constexpr const char* kReservedSuffix = ".submission";

// The content hash a result was written with ("" when it has none or cannot be read).
std::string stored_content_hash(const fs::path& summary) {
  std::ifstream in(summary);
  try {
    nlohmann::json doc = nlohmann::json::parse(in);
    return doc.is_object() ? doc.value("content_hash", "") : "";
  } catch (const nlohmann::json::exception&) {
    return "";
  }
}

bool batch_own_name(const std::string& name) {
  return std::any_of(std::begin(kBatchOwnNames), std::end(kBatchOwnNames),
                     [&](const char* own) { return lower_case(name) == own; });
}

// A submission's result folder in a batch: its name, unless that is one of the
// batch's own (a student folder named gradebook.csv must not take the gradebook's place).
std::string result_folder_name(const std::string& name) { return batch_own_name(name) ? name + kReservedSuffix : name; }

// An older kit-grade wrote a submission named like the batch's files into a
// folder of that name (DIR/gradebook.csv/), which then stopped every batch from
// writing its gradebook: such a result folder is moved to its new name.
void move_reserved_result_folders(const fs::path& out) {
  for (const char* own : kBatchOwnNames) {
    fs::path old_dir = out / own, new_dir = out / (std::string(own) + kReservedSuffix);
    struct stat st {};
    if (lstat(old_dir.c_str(), &st) != 0 || !S_ISDIR(st.st_mode) || !fs::exists(old_dir / "results.json")) continue;
    std::error_code ec;
    if (fs::exists(fs::symlink_status(new_dir, ec))) {
      fs::remove_all(old_dir, ec);  // the result it held was replaced since
      std::printf("kit-grade: removed %s, a result folder an older kit-grade wrote in the place of the batch's %s\n",
                  old_dir.c_str(), own);
    } else {
      fs::rename(old_dir, new_dir, ec);
      std::printf("kit-grade: moved %s to %s: an older kit-grade wrote that submission's result in the place of "
                  "the batch's %s\n",
                  old_dir.c_str(), new_dir.c_str(), own);
    }
    if (ec) throw Error(old_dir.string() + ": cannot move it out of the batch's way: " + ec.message());
  }
}

// Staging folders (".name.partial") a batch killed while writing left behind:
// with the lock held, no other batch is writing them.
void remove_partial_results(const fs::path& out) {
  std::error_code ec;
  for (fs::directory_iterator it(out, ec), end; !ec && it != end; it.increment(ec)) {
    std::string name = it->path().filename().string();
    const std::string suffix = ".partial";
    if (name.size() <= suffix.size() + 1 || name[0] != '.' ||
        name.compare(name.size() - suffix.size(), suffix.size(), suffix) != 0)
      continue;
    std::error_code remove_ec;
    fs::remove_all(it->path(), remove_ec);
  }
}

// An exclusive flock on DIR/.kit-grade.lock for as long as a batch runs: two
// batches writing one output folder would rename result folders under each
// other and interleave the gradebook. The kernel releases it however the run
// ends (kill -9 included); the file holds the owner's process id for the message.
class BatchLock {
 public:
  explicit BatchLock(const fs::path& out) {
    fs::path path = out / kBatchLockFile;
    fd_ = open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC | O_NOFOLLOW, 0644);
    if (fd_ < 0) throw Error(path.string() + ": cannot open the batch's lock file: " + std::strerror(errno));
    if (flock(fd_, LOCK_EX | LOCK_NB) != 0) {
      int err = errno;
      char text[32] = {0};
      ssize_t n = pread(fd_, text, sizeof text - 1, 0);
      std::string holder = n > 0 ? trimmed(std::string(text, static_cast<size_t>(n))) : "";
      close(fd_);
      if (err == EWOULDBLOCK)
        throw Error(out.string() + ": another kit-grade batch (pid " + (holder.empty() ? "unknown" : holder) +
                    ") is grading into this folder and holds its lock " + path.string() +
                    "; wait for it to finish, or grade into another --out");
      throw Error(path.string() + ": cannot lock: " + std::strerror(err));
    }
    std::string pid = std::to_string(getpid()) + "\n";
    if (ftruncate(fd_, 0) != 0 || pwrite(fd_, pid.data(), pid.size(), 0) < 0) {
      // The lock holds all the same; only the message of a second run lacks the pid.
    }
  }
  ~BatchLock() { close(fd_); }
  BatchLock(const BatchLock&) = delete;
  BatchLock& operator=(const BatchLock&) = delete;

 private:
  int fd_ = -1;
};

}  // namespace

int grade_batch(const fs::path& folder, const Options& options) {
  std::error_code ec;
  if (!fs::is_directory(folder, ec)) throw Error(folder.string() + ": not a folder of submissions");
  std::string why;
  if (!writable_folder(options.out, &why)) throw Error(why);
  BatchLock lock(options.out);
  move_reserved_result_folders(options.out);
  remove_partial_results(options.out);
  std::vector<fs::path> sources;
  for (const auto& entry : fs::directory_iterator(folder)) {
    std::string name = entry.path().filename().string();
    if (name.empty() || name[0] == '.') continue;
    if (entry.is_directory() || (is_zip(entry.path()) && entry.is_regular_file())) sources.push_back(entry.path());
  }
  std::sort(sources.begin(), sources.end());
  // Two sources with one result folder (alice/ and alice.zip) would share it.
  std::set<std::string> folders;
  std::vector<std::pair<std::string, std::string>> all_names;  // submission, result folder
  std::vector<std::string> changed, unhashed, renamed;
  std::set<std::string> changed_set;
  std::vector<Entry> entries;
  size_t skipped = 0;
  for (const fs::path& source : sources) {
    std::string name = submission_name(source);
    std::string folder_name = result_folder_name(name);
    if (!folders.insert(folder_name).second) {
      std::fprintf(stderr, "kit-grade: %s: skipped, another submission has the result folder '%s'\n", source.c_str(),
                   folder_name.c_str());
      continue;
    }
    if (folder_name != name) renamed.push_back(name + " -> " + folder_name + "/");
    all_names.push_back({name, folder_name});
    const fs::path final_dir = options.out / folder_name;
    std::string hash = content_hash(source);
    if (!options.force && fs::exists(final_dir / "results.json")) {
      // A result stands while the submission holds what it held when graded.
      std::string stored = stored_content_hash(final_dir / "summary.json");
      if (stored.empty()) unhashed.push_back(name);  // written before content hashes were stored
      if (stored.empty() || stored == hash) {
        ++skipped;
        continue;
      }
      changed.push_back(name);
      changed_set.insert(name);
    }
    Entry e;
    e.source = source;
    e.result_dir = options.out / ("." + folder_name + ".partial");
    e.final_dir = final_dir;
    e.content_hash = hash;
    entries.push_back(std::move(e));
  }
  if (!renamed.empty()) {
    std::string list;
    for (const std::string& r : renamed) list += (list.empty() ? "" : ", ") + r;
    std::printf("kit-grade: named like the batch's own files, so their results go in folders named otherwise: %s\n",
                list.c_str());
  }
  std::printf("kit-grade: %zu submissions in %s: %zu to grade%s, %zu already graded%s\n", all_names.size(),
              folder.c_str(), entries.size(),
              changed.empty() ? "" : (" (" + std::to_string(changed.size()) + " changed since graded)").c_str(), skipped,
              skipped ? " (--force regrades them)" : "");
  if (!changed.empty()) {
    std::string list;
    for (const std::string& n : changed) list += (list.empty() ? "" : ", ") + n;
    std::printf("kit-grade: regrading, their files changed since their results were written: %s\n", list.c_str());
  }
  if (!unhashed.empty())
    std::printf("kit-grade: %zu results have no content hash (written by an older kit-grade): kept as they are; "
                "--force regrades them\n",
                unhashed.size());
  std::fflush(stdout);
  Run run = make_run(options, true);
  size_t done = 0;
  bool grader_error = false;
  auto t0 = Clock::now();
  bool completed = run_entries(run, entries, [&](Entry& e) {
    const fs::path& final_dir = e.final_dir;
    fs::create_directories(e.result_dir);
    write_results(e.result_dir, e.outcome);
    std::error_code remove_ec;
    fs::remove_all(final_dir, remove_ec);
    fs::rename(e.result_dir, final_dir);  // atomic: a result folder is complete or absent
    grader_error = grader_error || e.outcome.grader_error();
    std::string problems;
    for (const auto& [n, lab] : e.outcome.labs)
      if (lab.status != kGraded) problems += " lab" + std::to_string(n) + ":" + lab.status;
    std::printf("[%zu/%zu] %s: %s/%s  (%.1f s)%s%s\n", ++done, entries.size(), e.outcome.name.c_str(),
                format_points(e.outcome.total()).c_str(), format_points(e.outcome.max_total()).c_str(), e.outcome.seconds,
                problems.c_str(), changed_set.count(e.outcome.name) ? "  [regraded: changed]" : "");
    std::fflush(stdout);
  });
  remove_run_temp(run);
  const BatchSummaries summaries = read_batch_summaries(options.out, all_names);
  write_gradebook(options.out, summaries, options.labs);
  write_class_summary(options.out, summaries, options.labs);
  std::printf("kit-grade: %zu graded in %.1f s; gradebook: %s; the class: %s\n", done, seconds_since(t0),
              (options.out / "gradebook.csv").c_str(), (options.out / "class-summary.html").c_str());
  if (!completed) return 130;
  return grader_error ? 2 : 0;
}

}  // namespace kit::grade
