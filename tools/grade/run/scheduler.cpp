#include "run/scheduler.h"

#include <string.h>

#include <algorithm>
#include <cstdio>
#include <deque>
#include <memory>
#include <optional>

#include "files/files.h"
#include "frames/checks.h"
#include "gl/pass_clock.h"
#include "run/lab_results.h"
#include "worker/render_worker.h"

namespace fs = std::filesystem;

namespace kit::grade {

namespace {

struct Task {
  size_t entry;
  int lab;
  bool alone = false;  // to be the first lab of a fresh worker (LabScheduler::lab_ended says when)
};

// A render worker (render_worker.h) of one submission and the lab it renders now.
struct Worker {
  size_t entry = 0;
  std::unique_ptr<Child> child;
  int lab = 0;        // the lab in progress; 0 when none
  int labs_done = 0;  // labs it has reported
};

// A lab whose rendering ended, reported or not, and how.
struct Rendered {
  Task task;
  Outcome outcome;
};

// The scheduler of run_entries: a queue of labs, the render workers rendering them, and the
// labs whose rendering ended, waiting to be compared.
class LabScheduler {
 public:
  LabScheduler(Run& run, std::vector<Entry>& entries, const Finished& finished);
  // Until every lab is graded (true) or a signal stops the workers (false).
  bool run();

 private:
  void complete(Entry& e, LabOutcome lab);
  void skip_unready();
  void give_lab(Worker& w);
  void start_workers();
  void lab_ended(const Worker& w, const Outcome& o, bool verdict);
  void poll_workers();
  void grade_rendered();

  Run& run_;
  std::vector<Entry>& entries_;
  const Finished& finished_;
  // Before the workers: they are stopped (destroyed) while SIGINT and SIGTERM are still held.
  InterruptGuard interrupts_;
  std::deque<Task> queue_;
  size_t slots_;
  std::vector<Worker> workers_;
  std::vector<Rendered> rendered_;
};

LabScheduler::LabScheduler(Run& run, std::vector<Entry>& entries, const Finished& finished)
    : run_(run), entries_(entries), finished_(finished), slots_(static_cast<size_t>(std::max(1, run.options.jobs))) {
  const std::vector<int> order = lab_start_order(run.options.labs, run.options.jobs);
  for (size_t i = 0; i < entries.size(); ++i) {
    entries[i].labs_left = run.options.labs.size();
    for (int lab : order) queue_.push_back({i, lab});
  }
}

// Records a lab of `e`; the entry's last hands it on and frees what it held.
void LabScheduler::complete(Entry& e, LabOutcome lab) {
  lab.folder = e.prepared->labs.at(lab.lab).folder;
  e.outcome.labs[lab.lab] = std::move(lab);
  if (--e.labs_left > 0) return;
  e.outcome.seconds = seconds_since(e.started);
  finished_(e);
  e.outcome = SubmissionOutcome();  // reported: free it before the next submission
  e.prepared.reset();
  if (!run_.options.keep_temp) {
    std::error_code ec;
    fs::remove_all(e.temp, ec);
  }
}

// Labs at the front of the queue whose files could not be prepared are complete at once.
void LabScheduler::skip_unready() {
  while (!queue_.empty()) {
    Entry& e = entries_[queue_.front().entry];
    if (!e.prepared) prepare_entry(run_, e);
    const LabFiles& files = e.prepared->labs.at(queue_.front().lab);
    if (files.ready) return;
    LabOutcome lab = empty_lab(run_, queue_.front().lab);
    lab.status = files.status;
    lab.message = trimmed(files.message);
    queue_.pop_front();
    complete(e, std::move(lab));
  }
}

// The next lab of the worker's submission, or stop when there is none it may take.
void LabScheduler::give_lab(Worker& w) {
  skip_unready();
  if (!queue_.empty() && queue_.front().entry == w.entry && !(queue_.front().alone && w.labs_done > 0)) {
    w.lab = queue_.front().lab;
    queue_.pop_front();
    fs::create_directories(lab_folder(entries_[w.entry].temp, w.lab));
    w.child->send_task(w.lab);  // a worker already gone ends the lab: poll() says how
    return;
  }
  w.child->send_task(0);
  w.lab = 0;
}

// A worker for each free slot while labs wait, each for the submission of the first.
void LabScheduler::start_workers() {
  for (skip_unready(); workers_.size() < slots_ && !queue_.empty(); skip_unready()) {
    Entry& e = entries_[queue_.front().entry];
    const RenderWorker spec{e.prepared->lab_root, e.temp, run_.options.backend, run_.options.device, &run_.scenes,
                            &run_.probes_reference, run_.renders_describing()};
    Worker w;
    w.entry = queue_.front().entry;
    w.child = std::make_unique<Child>(Child::fork_worker(
        [spec](TaskChannel& channel) { return spec.serve(channel); }, run_.options.limits,
        static_cast<int>(run_.options.labs.size()), e.temp / "worker.log", render_setup(run_, e, e.temp)));
    give_lab(w);
    workers_.push_back(std::move(w));
  }
}

// The lab `w` renders ended as `o`: compared, or rendered again alone when the worker
// ended abnormally (`verdict`: the lab's own status, reported) after another lab.
void LabScheduler::lab_ended(const Worker& w, const Outcome& o, bool verdict) {
  if (!verdict && render_again_alone(o, w.labs_done))
    queue_.push_front({w.entry, w.lab, true});
  else
    rendered_.push_back({{w.entry, w.lab}, o});
}

// Reads what each worker has reported and removes the workers that ended.
void LabScheduler::poll_workers() {
  for (size_t i = 0; i < workers_.size();) {
    Worker& w = workers_[i];
    const bool ended = w.child->poll();  // a report sent before the worker ended is read below
    while (const std::optional<Child::TaskResult> report = w.child->next_report()) {
      if (report->task != w.lab) continue;
      const Outcome& o = report->outcome;
      lab_ended(w, o, o.kind == Outcome::Kind::Exited);
      w.lab = 0;
      ++w.labs_done;
      // The next lab renders while this one is compared; after a lab that did not
      // render, the worker ends and the next lab gets a fresh one.
      if (!ended && o.kind == Outcome::Kind::Exited && o.code == kWorkerOk) give_lab(w);
    }
    if (!ended) {
      ++i;
      continue;
    }
    if (w.lab != 0) lab_ended(w, w.child->outcome(), false);  // it ended during a lab
    workers_.erase(workers_.begin() + static_cast<std::ptrdiff_t>(i));
  }
}

// Compares each lab whose rendering ended.
void LabScheduler::grade_rendered() {
  for (Rendered& done : rendered_) {
    Entry& e = entries_[done.task.entry];
    complete(e, grade_rendered_lab(run_, e, done.task.lab, done.outcome));
  }
  rendered_.clear();
}

bool LabScheduler::run() {
  while (!queue_.empty() || !workers_.empty()) {
    if (int sig = interrupts_.pending()) {
      std::fprintf(stderr, "kit-grade: %s: stopping the renderers\n", strsignal(sig));
      workers_.clear();  // each Child kills its process group
      return false;
    }
    start_workers();
    poll_workers();
    if (rendered_.empty()) {
      poll_pause();
      continue;
    }
    // The next labs render while this process compares the finished ones.
    start_workers();
    grade_rendered();
  }
  return true;
}

}  // namespace

std::vector<int> lab_start_order(const std::vector<int>& labs, int jobs) {
  // The last lab first: each stage runs every earlier stage's passes and adds its own
  // (lab 6 precomputes its maps, over half of its time), so the longest lab starts
  // first and the short ones fill in beside it (median of nine runs at --jobs 2: 1.51 s
  // against 1.57 s in lab order). Then, as soon as a worker is free, the lab with the most
  // checks: its comparison is the costliest (lab 1's 15, 0.06 s), and as the last lab it ran
  // after every other lab had rendered, one core idle; started early, it is compared while the
  // others render (warm, farm-bench, three runs of 30 pairs: wall 0.96, 0.97 and 0.99).
  std::vector<int> order(labs.rbegin(), labs.rend());
  const auto most_checks = std::max_element(order.begin(), order.end(), [](int a, int b) {
    return lab_checks(a).size() < lab_checks(b).size();
  });
  const auto next_started =
      order.begin() + std::min<std::ptrdiff_t>(std::max(1, jobs), static_cast<std::ptrdiff_t>(order.size()));
  if (most_checks > next_started) std::rotate(next_started, most_checks, most_checks + 1);
  return order;
}

bool render_again_alone(const Outcome& ended, int labs_before) {
  // Only RLIMIT_AS spans a worker's life, and a crash may follow from an earlier lab's
  // state; a timeout or the CPU limit counts from the lab's own start, and a second run
  // would only make the student wait as long again.
  const bool own_time = ended.kind == Outcome::Kind::TimedOut || ended.kind == Outcome::Kind::CpuLimit;
  return labs_before > 0 && !own_time;
}

bool run_entries(Run& run, std::vector<Entry>& entries, const Finished& finished) {
  return LabScheduler(run, entries, finished).run();
}

}  // namespace kit::grade
