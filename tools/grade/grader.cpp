#include "grader.h"

#include <OpenImageIO/imageio.h>
#include <nlohmann/json.hpp>
#include <signal.h>
#include <stdlib.h>

#include <algorithm>
#include <cstdio>
#include <deque>
#include <fstream>
#include <memory>
#include <optional>
#include <set>

#include "error.h"
#include "references.h"
#include "renderer.h"
#include "render_child.h"
#include "report.h"
#include "scene.h"
#include "stages.h"
#include "submission.h"

namespace fs = std::filesystem;

namespace kit::grade {

namespace {

using Clock = std::chrono::steady_clock;
// "1,2,3", or "none".
std::string labs_list(const std::vector<int>& labs) {
  std::string out;
  for (int lab : labs) out += (out.empty() ? "" : ",") + std::to_string(lab);
  return out.empty() ? "none" : out;
}

double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

// How much of a child's error file and log the messages quote.
constexpr size_t kErrorBytes = 64 * 1024;
constexpr size_t kLogTailBytes = 2 * 1024;
// Report images live in this folder of a result folder.
constexpr const char* kImageFolder = "img";

// One grading run: the settings, what every submission shares (config,
// scenes, references) and the run's private temporary folder.
struct Run {
  const Options& options;
  Config config;
  std::map<std::string, Scene> scenes;
  std::map<std::string, Image> references;
  std::map<std::string, Image>* collect = nullptr;  // --update-references: keep the raw renders instead
  fs::path temp;
};

struct Entry {
  fs::path source;
  fs::path result_dir;  // report images are written here (a staging folder in a batch)
  std::string content_hash;  // computed before grading, stored in summary.json
  SubmissionOutcome outcome;
  std::optional<PreparedSubmission> prepared;
  fs::path temp;
  size_t labs_left = 0;
  Clock::time_point started;
};

struct Task {
  size_t entry;
  int lab;
};

struct Running {
  Task task;
  fs::path dir;
  std::unique_ptr<Child> child;
};

using Finished = std::function<void(Entry&)>;

// The parent forks render children: OpenImageIO and OpenEXR must work in the
// calling thread, so no worker of theirs can hold a lock at a fork (the images
// are small; threads would not pay for themselves anyway).
void single_threaded_image_io() {
  OIIO::attribute("threads", 1);
  OIIO::attribute("exr_threads", -1);
}

// A fresh private folder (mode 0700) under `base`.
fs::path make_temp_dir(const fs::path& base, const std::string& prefix) {
  std::string pattern = (base / (prefix + "XXXXXX")).string();
  if (!mkdtemp(pattern.data())) throw Error("kit-grade: cannot create a temporary folder in " + pattern);
  return pattern;
}

std::map<std::string, Scene> load_scenes(const std::vector<int>& labs) {
  std::map<std::string, Scene> scenes;
  for (int lab : labs)
    for (const RenderSpec* spec : lab_renders(lab))
      if (!scenes.count(spec->scene)) scenes.emplace(spec->scene, load_scene(resolve_scene(spec->scene)));
  return scenes;
}

LabOutcome empty_lab(const Run& run, int lab) {
  LabOutcome out;
  out.lab = lab;
  for (const Check* check : lab_checks(lab)) {
    CheckOutcome c;
    c.check = check;
    c.max_score = run.config.max_score(*check);
    out.checks.push_back(c);
  }
  return out;
}

std::string read_text(const fs::path& path) { return read_tail(path, kErrorBytes); }

std::string trimmed(std::string text) {
  while (!text.empty() && (text.back() == '\n' || text.back() == ' ')) text.pop_back();
  return text;
}

// Sets status and message from how the child ended; true when it rendered everything.
bool classify_child(const Run& run, const Outcome& o, const fs::path& dir, LabOutcome& lab) {
  const Limits& limits = run.options.limits;
  std::string log = trimmed(read_tail(dir / "child.log", kLogTailBytes));
  std::string log_part = log.empty() ? "" : "\n\nlast output of the renderer:\n" + log;
  char buf[256];
  if (o.kind == Outcome::Kind::TimedOut) {
    std::snprintf(buf, sizeof buf, "rendering did not finish within %.0f s and was stopped (an endless loop in a shader?)",
                  limits.wall_seconds);
    lab.status = kTimeout;
    lab.message = buf;
    return false;
  }
  if (o.kind == Outcome::Kind::Signaled) {
    if (o.code == SIGXCPU) {
      lab.status = kTimeout;
      lab.message = "the renderer used more than " + std::to_string(limits.cpu_seconds) +
                    " s of CPU time and was stopped (an endless loop in a shader?)";
    } else {
      lab.status = kCrash;
      lab.message = "the renderer crashed (" + o.describe() + ") while running this lab's shaders" + log_part;
    }
    return false;
  }
  switch (o.code) {
    case kChildOk: return true;
    case kChildShaderError:
      lab.status = kCompileError;
      lab.message = trimmed(read_text(dir / "error.txt"));
      return false;
    case kChildEnvironmentError:
      lab.status = kGraderError;
      lab.message = "the grader could not render: " + trimmed(read_text(dir / "error.txt"));
      return false;
    case kChildRenderError:
      lab.status = kCrash;
      lab.message = "the frame could not be rendered: " + trimmed(read_text(dir / "error.txt"));
      return false;
    default: break;
  }
  lab.status = kCrash;
  bool memory = log.find("bad_alloc") != std::string::npos || log.find("out of memory") != std::string::npos;
  lab.message = memory ? "the renderer ran out of memory (limit " + std::to_string(limits.address_space_mib) + " MiB)" + log_part
                       : "the renderer stopped with " + o.describe() + log_part;
  return false;
}

void write_report_images(const Run& run, const fs::path& result_dir, const Check& check, const Image& image,
                         const Image& reference, CheckOutcome& c) {
  std::string base = std::string(kImageFolder) + "/lab" + std::to_string(check.lab) + "-" + check.key;
  c.image = base + ".png";
  c.reference = base + ".ref.png";
  c.diff = base + ".diff.png";
  Metric shown = check.metric == Metric::Changes ? Metric::Ldr : check.metric;
  write_image((result_dir / c.image).string(), display_image(shown, image, reference));
  write_image((result_dir / c.diff).string(), c.comparison.diff);
  if (check.metric == Metric::Changes) {  // its "reference" is the submission's own render
    write_image((result_dir / c.reference).string(), display_image(shown, reference, reference));
    return;
  }
  // A reference looks the same in every submission's report: encoded once per run, then copied.
  fs::path cached = run.temp / "reference-png" / (check.reference + "." + metric_name(check.metric) + ".png");
  if (!fs::exists(cached)) {
    fs::create_directories(cached.parent_path());
    write_image(cached.string(), display_image(shown, reference, reference));
  }
  fs::copy_file(cached, result_dir / c.reference, fs::copy_options::overwrite_existing);
}

// Compares every check of a lab whose child rendered it.
void compare_lab(const Run& run, const fs::path& dir, const fs::path& result_dir, LabOutcome& lab) {
  auto t0 = Clock::now();
  nlohmann::json child;
  try {
    std::ifstream in(dir / "child.json");
    child = nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception&) {
    lab.status = kCrash;
    lab.message = "the renderer left no report (child.json)";
    return;
  }
  lab.render_ms = 1000.0 * child["seconds"].value("render", 0.0);
  for (const auto& [key, value] : child["seconds"].items())
    if (value.is_number()) lab.child_timings[key] = value.get<double>();
  lab.child_vm_peak_kib = child.value("vm_peak_kib", 0L);
  std::map<std::string, Image> renders;
  try {
    for (const RenderSpec* spec : lab_renders(lab.lab)) renders[spec->id] = read_raw_image(raw_image_path(dir, spec->id));
  } catch (const Error& e) {
    lab.status = kCrash;
    lab.message = e.what();
    return;
  }
  if (run.collect) {
    for (auto& [id, image] : renders) (*run.collect)[id] = std::move(image);
    lab.status = kGraded;
    return;
  }
  fs::create_directories(result_dir / kImageFolder);
  lab.status = kGraded;
  for (CheckOutcome& c : lab.checks) {
    const Check& check = *c.check;
    const Image& image = renders.at(check.image);
    const Image& reference = check.metric == Metric::Changes ? renders.at(check.reference) : run.references.at(check.reference);
    c.comparison = compare_images(check.metric, run.config.tolerance(check.metric), image, reference);
    size_t hdr_bad = child.contains("hdr_non_finite") ? child["hdr_non_finite"].value(check.image, size_t{0}) : 0;
    if (hdr_bad > 0 && check.metric != Metric::Changes) {
      c.comparison.passed = false;
      c.comparison.note = "the HDR buffer behind this image holds " + std::to_string(hdr_bad) +
                          " NaN or Inf pixels: " + kNonFiniteAdvice;
    }
    c.compared = true;
    c.passed = c.comparison.passed;
    c.score = c.passed ? c.max_score : 0;
    write_report_images(run, result_dir, check, image, reference, c);
    c.comparison.diff = Image();  // written: a batch keeps no images in memory
  }
  lab.compare_seconds = since(t0);
}

void prepare(const Run& run, Entry& e) {
  e.started = Clock::now();
  e.temp = make_temp_dir(run.temp, "submission-");
  e.prepared = prepare_submission(e.source, run.options.labs, e.temp, run.options.limits);
  e.outcome.name = e.prepared->name;
  e.outcome.source = e.source;
  e.outcome.problem = e.prepared->problem;
  e.outcome.notes = e.prepared->notes;
  e.outcome.content_hash = e.content_hash;
}

// Runs every lab of every entry, at most options.jobs children at a time;
// `finished` is called as each entry completes. Returns false when interrupted.
bool run_entries(Run& run, std::vector<Entry>& entries, const Finished& finished) {
  InterruptGuard interrupts;
  std::deque<Task> queue;
  for (size_t i = 0; i < entries.size(); ++i) {
    entries[i].labs_left = run.options.labs.size();
    for (int lab : run.options.labs) queue.push_back({i, lab});
  }
  std::vector<Running> running;
  auto complete = [&](Entry& e, LabOutcome lab) {
    lab.folder = e.prepared->labs.at(lab.lab).folder;
    e.outcome.labs[lab.lab] = std::move(lab);
    if (--e.labs_left > 0) return;
    e.outcome.seconds = since(e.started);
    finished(e);
    e.outcome = SubmissionOutcome();  // reported: free it before the next submission
    e.prepared.reset();
    if (!run.options.keep_temp) {
      std::error_code ec;
      fs::remove_all(e.temp, ec);
    }
  };
  auto start_tasks = [&] {
    while (!queue.empty() && running.size() < static_cast<size_t>(std::max(1, run.options.jobs))) {
      Task task = queue.front();
      queue.pop_front();
      Entry& e = entries[task.entry];
      if (!e.prepared) prepare(run, e);
      const LabFiles& files = e.prepared->labs.at(task.lab);
      if (!files.ready) {
        LabOutcome lab = empty_lab(run, task.lab);
        lab.status = files.status;
        lab.message = trimmed(files.message);
        complete(e, std::move(lab));
        continue;
      }
      fs::path dir = e.temp / ("lab" + std::to_string(task.lab));
      fs::create_directories(dir);
      RenderJob job{task.lab, e.prepared->lab_root, dir, run.options.backend, &run.scenes};
      auto child = std::make_unique<Child>(
          Child::fork_function([job] { return render_lab(job); }, run.options.limits, dir / "child.log"));
      running.push_back({task, dir, std::move(child)});
    }
  };
  while (!queue.empty() || !running.empty()) {
    if (int sig = interrupts.pending()) {
      std::fprintf(stderr, "kit-grade: %s: stopping the renderers\n", strsignal(sig));
      running.clear();  // each Child kills its process group
      return false;
    }
    start_tasks();
    std::vector<Running> finished;
    for (size_t i = 0; i < running.size();) {
      if (running[i].child->poll()) {
        finished.push_back(std::move(running[i]));
        running.erase(running.begin() + static_cast<std::ptrdiff_t>(i));
      } else {
        ++i;
      }
    }
    if (finished.empty()) {
      poll_pause();
      continue;
    }
    // The next labs render while this process compares the finished ones.
    start_tasks();
    for (Running& done : finished) {
      Entry& e = entries[done.task.entry];
      LabOutcome lab = empty_lab(run, done.task.lab);
      const Outcome& o = done.child->outcome();
      lab.child_seconds = o.wall_seconds;
      lab.child_cpu_seconds = o.cpu_seconds;
      lab.child_max_rss_kib = o.max_rss_kib;
      if (classify_child(run, o, done.dir, lab)) compare_lab(run, done.dir, e.result_dir, lab);
      std::ifstream child_report(done.dir / "child.json");
      if (child_report) {
        try {
          e.outcome.renderer = nlohmann::json::parse(child_report).value("renderer", "");
        } catch (const nlohmann::json::exception&) {
        }
      }
      complete(e, std::move(lab));
    }
  }
  return true;
}

Run make_run(const Options& options, bool need_references) {
  Run run{options, load_config(options.config.empty() ? default_config_path() : options.config), {}, {}, nullptr, {}};
  if (need_references)
    run.references = load_references(options.references.empty() ? default_references_dir() : options.references, options.labs);
  run.scenes = load_scenes(options.labs);
  const char* tmp = std::getenv("TMPDIR");
  run.temp = make_temp_dir(tmp && *tmp ? tmp : "/tmp", "kit-grade-");
  return run;
}

void remove_run_temp(const Run& run) {
  if (run.options.keep_temp) {
    std::fprintf(stderr, "kit-grade: temporary files kept in %s\n", run.temp.c_str());
    return;
  }
  std::error_code ec;
  fs::remove_all(run.temp, ec);
}

void print_submission(const SubmissionOutcome& s) {
  if (!s.problem.empty()) std::printf("%s: %s\n", s.name.c_str(), s.problem.c_str());
  for (const auto& [number, lab] : s.labs) std::printf("%s\n", lab_line(lab).c_str());
  std::printf("total: %s/%s\n", format_points(s.total()).c_str(), format_points(s.max_total()).c_str());
  std::fflush(stdout);
}

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

bool writable_folder(const fs::path& dir, std::string* why) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec || !fs::is_directory(dir)) {
    *why = dir.string() + ": cannot create the output folder" + (ec ? " (" + ec.message() + ")" : "");
    return false;
  }
  fs::path probe = dir / (".kit-grade-probe-" + std::to_string(getpid()));
  std::ofstream(probe) << "";
  bool ok = fs::exists(probe);
  fs::remove(probe, ec);
  if (!ok) *why = dir.string() + ": cannot write in the output folder";
  return ok;
}

}  // namespace

int LabOutcome::passed_checks() const {
  return static_cast<int>(std::count_if(checks.begin(), checks.end(), [](const CheckOutcome& c) { return c.passed; }));
}

Thousandths LabOutcome::score() const {
  Thousandths sum = 0;
  for (const CheckOutcome& c : checks) sum += c.score;
  return sum;
}

Thousandths LabOutcome::max_score() const {
  Thousandths sum = 0;
  for (const CheckOutcome& c : checks) sum += c.max_score;
  return sum;
}

Thousandths SubmissionOutcome::total() const {
  Thousandths sum = 0;
  for (const auto& [n, lab] : labs) sum += lab.score();
  return sum;
}

Thousandths SubmissionOutcome::max_total() const {
  Thousandths sum = 0;
  for (const auto& [n, lab] : labs) sum += lab.max_score();
  return sum;
}

bool SubmissionOutcome::grader_error() const {
  return std::any_of(labs.begin(), labs.end(), [](const auto& l) { return l.second.status == kGraderError; });
}

int grade_submission(const fs::path& submission, const Options& options) {
  single_threaded_image_io();
  std::error_code ec;
  if (!fs::exists(fs::symlink_status(submission, ec))) throw Error(submission.string() + ": no such folder or file");
  std::string why;
  if (!writable_folder(options.out, &why)) throw Error(why);
  Run run = make_run(options, true);
  std::vector<Entry> entries(1);
  entries[0].source = submission;
  entries[0].result_dir = options.out;
  entries[0].content_hash = content_hash(submission);
  bool grader_error = false;
  bool completed = run_entries(run, entries, [&](Entry& e) {
    write_results(options.out, e.outcome);
    if (!options.quiet) print_submission(e.outcome);
    grader_error = e.outcome.grader_error();
  });
  remove_run_temp(run);
  if (!completed) return 130;
  if (grader_error) {
    std::fprintf(stderr, "kit-grade: the grader could not render (see %s)\n", (options.out / "summary.json").c_str());
    return 2;
  }
  return 0;
}

int grade_batch(const fs::path& folder, const Options& options) {
  single_threaded_image_io();
  std::error_code ec;
  if (!fs::is_directory(folder, ec)) throw Error(folder.string() + ": not a folder of submissions");
  std::string why;
  if (!writable_folder(options.out, &why)) throw Error(why);
  std::vector<fs::path> sources;
  for (const auto& entry : fs::directory_iterator(folder)) {
    std::string name = entry.path().filename().string();
    if (name.empty() || name[0] == '.') continue;
    if (entry.is_directory() || (is_zip(entry.path()) && entry.is_regular_file())) sources.push_back(entry.path());
  }
  std::sort(sources.begin(), sources.end());
  // Two sources with one name (alice/ and alice.zip) would share a result folder.
  std::set<std::string> names;
  std::vector<std::string> all_names, changed, unhashed;
  std::set<std::string> changed_set;
  std::vector<Entry> entries;
  size_t skipped = 0;
  for (const fs::path& source : sources) {
    std::string name = submission_name(source);
    if (!names.insert(name).second) {
      std::fprintf(stderr, "kit-grade: %s: skipped, another submission is also named '%s'\n", source.c_str(), name.c_str());
      continue;
    }
    all_names.push_back(name);
    std::string hash = content_hash(source);
    if (!options.force && fs::exists(options.out / name / "results.json")) {
      // A result stands while the submission holds what it held when graded.
      std::string stored = stored_content_hash(options.out / name / "summary.json");
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
    e.result_dir = options.out / ("." + name + ".partial");
    e.content_hash = hash;
    entries.push_back(std::move(e));
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
    fs::path final_dir = options.out / e.outcome.name;
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
  write_gradebook(options.out, all_names, options.labs);
  std::printf("kit-grade: %zu graded in %.1f s; gradebook: %s\n", done, since(t0), (options.out / "gradebook.csv").c_str());
  if (!completed) return 130;
  return grader_error ? 2 : 0;
}

int update_references(const Options& options) {
  single_threaded_image_io();
  Options o = options;
  o.labs.clear();
  for (const Stage& s : stages()) o.labs.push_back(s.number);
  Run run = make_run(o, false);
  std::map<std::string, Image> collected;
  run.collect = &collected;
  std::vector<Entry> entries(1);
  entries[0].source = kit_root() / "solutions";
  entries[0].result_dir = run.temp / "unused";
  std::string failures, renderer;
  bool completed = run_entries(run, entries, [&](Entry& e) {
    renderer = e.outcome.renderer;
    for (const auto& [n, lab] : e.outcome.labs)
      if (lab.status != kGraded) failures += "\n  " + lab_title(n) + ": " + lab.status + ": " + lab.message;
  });
  remove_run_temp(run);
  if (!completed) return 130;
  if (!failures.empty()) throw Error("the solutions did not render:" + failures);
  fs::path dir = o.references.empty() ? default_references_dir() : o.references;
  write_references(dir, collected, renderer);
  std::printf("kit-grade: %zu references written to %s (%s); check them with --check-references\n",
              reference_renders().size(), dir.c_str(), renderer.c_str());
  return 0;
}

int check_references(const Options& options) {
  single_threaded_image_io();
  Options o = options;
  // The labs whose solutions this kit holds: every lab in the instructor's kit, the
  // released ones in a student copy (whose references are checked all the same).
  o.labs = labs_with_solutions();
  fs::path dir = o.references.empty() ? default_references_dir() : o.references;
  std::vector<std::string> stale = manifest_differences(dir);
  if (stale.empty() && !o.labs.empty()) {
    Run run = make_run(o, true);
    // Stale means: any pixel of a solution over its per-pixel threshold (no share of failing pixels allowed).
    for (auto& [metric, tolerance] : run.config.tolerances) tolerance.fail_percent = 0.0;
    std::vector<Entry> entries(1);
    entries[0].source = kit_root() / "solutions";
    entries[0].result_dir = run.temp / "result";
    bool completed = run_entries(run, entries, [&](Entry& e) {
      for (const auto& [n, lab] : e.outcome.labs) {
        if (lab.status != kGraded) stale.push_back(lab_title(n) + ": " + lab.status + ": " + lab.message);
        for (const CheckOutcome& c : lab.checks)
          if (lab.status == kGraded && !c.passed)
            stale.push_back(lab_title(n) + ": " + c.check->title + ": " + c.comparison.note +
                            (c.comparison.note.empty() ? "" : "; ") + c.comparison.summary);
      }
    });
    remove_run_temp(run);
    if (!completed) return 130;
  }
  if (stale.empty()) {
    std::printf("kit-grade: the references in %s match the check list (%zu images) and the solutions of labs %s\n",
                dir.c_str(), reference_renders().size(), labs_list(o.labs).c_str());
    return 0;
  }
  std::printf("kit-grade: the references in %s are stale (run kit-grade --update-references):\n", dir.c_str());
  for (const std::string& s : stale) std::printf("  %s\n", s.c_str());
  return 1;
}

}  // namespace kit::grade
