#include "grader.h"

#include <nlohmann/json.hpp>
#include <signal.h>
#include <stdlib.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <deque>
#include <fstream>
#include <memory>

#include "base/error.h"
#include "files.h"
#include "grading_run.h"
#include "lab_verdict.h"
#include "gl/pass_clock.h"
#include "references.h"
#include "render/renderer.h"
#include "render_child.h"
#include "report.h"
#include "scene/scene.h"
#include "render/stages.h"
#include "submission.h"

namespace fs = std::filesystem;

namespace kit::grade {

namespace {

// How much of a child's error file and log the messages quote.
constexpr size_t kErrorBytes = 64 * 1024;
constexpr size_t kLogTailBytes = 2 * 1024;
// Report images live in this folder of a result folder.
constexpr const char* kImageFolder = "img";

struct Task {
  size_t entry;
  int lab;
  bool alone = false;  // to be the first lab of a fresh worker (run_entries says when)
};

// A render worker (render_child.h) of one submission and the lab it renders now.
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

// A run's temporary folder: kRunTempPrefix, the process id, '-' and mkdtemp's six characters.
constexpr const char* kRunTempPrefix = "kit-grade-";
// What --keep-temp renames it to ("kit-grade-kept-<pid>-XXXXXX"): no later run removes it.
constexpr const char* kKeptTempPrefix = "kit-grade-kept-";

// A fresh private folder (mode 0700) under `base`.
fs::path make_temp_dir(const fs::path& base, const std::string& prefix) {
  std::string pattern = (base / (prefix + "XXXXXX")).string();
  if (!mkdtemp(pattern.data())) throw Error("kit-grade: cannot create a temporary folder in " + pattern);
  return pattern;
}

std::map<std::string, Scene> load_scenes(const std::vector<int>& labs, bool describing) {
  std::map<std::string, Scene> scenes;
  for (int lab : labs)
    for (const RenderSpec* spec : lab_renders(lab, describing))
      if (!scenes.count(spec->scene)) scenes.emplace(spec->scene, load_scene(resolve_scene(spec->scene)));
  return scenes;
}

LabOutcome empty_lab(const Run& run, int lab) { return lab_outcome(run.config, lab); }

std::string read_text(const fs::path& path) { return read_tail(path, kErrorBytes); }

// Sets status and message from how the child ended; true when it rendered everything.
bool classify_child(const Outcome& o, const fs::path& dir, LabOutcome& lab) {
  std::string log = trimmed(read_tail(dir / "child.log", kLogTailBytes));
  std::string log_part = log.empty() ? "" : "\n\nlast output of the renderer:\n" + log;
  char buf[320];
  switch (o.kind) {
    case Outcome::Kind::TimedOut:
      // The backstop: the CPU limit ends a shader that loops; this one a child that
      // makes no progress at all, or a machine far too busy to render in time.
      std::snprintf(buf, sizeof buf,
                    "rendering did not finish within %.0f s of wall-clock time (--timeout; it had used %.1f s of CPU "
                    "time) and was stopped (an endless loop in a shader, or a machine too busy to render?)",
                    o.wall_limit, o.cpu_seconds);
      lab.status = kTimeout;
      lab.message = buf;
      return false;
    case Outcome::Kind::CpuLimit:
      lab.status = kTimeout;
      lab.message = "the renderer used more than " + std::to_string(o.cpu_limit) +
                    " s of CPU time (--cpu-limit) and was stopped (an endless loop in a shader?)";
      return false;
    case Outcome::Kind::OutOfMemory:
      lab.status = kCrash;
      lab.message = o.describe() + ": the renderer ran out of memory while running this lab's shaders (its address "
                    "space is limited by --memory-limit)" + log_part;
      return false;
    case Outcome::Kind::Signaled:
      lab.status = kCrash;
      lab.message = "the renderer crashed (" + o.describe() + ") while running this lab's shaders" + log_part;
      return false;
    case Outcome::Kind::Running:
    case Outcome::Kind::Exited: break;
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
    case kChildMapError:
      lab.status = kNonFiniteMap;
      lab.message = trimmed(read_text(dir / "error.txt"));
      return false;
    case kChildRenderError:
      lab.status = kCrash;
      lab.message = "the frame could not be rendered: " + trimmed(read_text(dir / "error.txt"));
      return false;
    default: break;
  }
  lab.status = kCrash;
  lab.message = "the renderer stopped with " + o.describe() + log_part;
  return false;
}

// cache_png writes `cached`, a PNG in the reference cache, from make() unless it is there;
// link_cached_png then makes `destination` a link to it, or a copy where the result folder
// is on another file system. A linked file costs a fraction of encoding one (a new file
// costs more than its bytes: kSingleFileCacheVariable says why). False when the cache
// cannot hold it: the caller writes its own file.
template <typename Make>
bool cache_png(const fs::path& cached, const Make& make) {
  std::error_code ec;
  if (cached.empty()) return false;
  if (fs::exists(cached, ec)) return true;
  fs::path temp = cached;
  temp += ".tmp-" + std::to_string(getpid()) + ".png";
  try {
    write_image(temp.string(), make(), PngEffort::Fastest);
    fs::rename(temp, cached);  // a run beside this one links the whole file or writes its own
  } catch (const std::exception&) {
    fs::remove(temp, ec);
    return false;
  }
  return true;
}

template <typename Make>
bool link_cached_png(const fs::path& cached, const fs::path& destination, const Make& make) {
  if (!cache_png(cached, make)) return false;
  std::error_code ec;
  fs::remove(destination, ec);
  fs::create_hard_link(cached, destination, ec);
  if (ec) fs::copy_file(cached, destination, fs::copy_options::overwrite_existing);
  return true;
}

// Writes a report image as a new file: the path may name a cached PNG linked there by an
// earlier run into the same folder, and writing through the link would change the cache.
void write_report_png(const fs::path& path, const Image& image) {
  std::error_code ec;
  fs::remove(path, ec);
  write_image(path.string(), image, PngEffort::Fastest);
}

bool same_values(const Image& a, const Image& b) {
  return a.width == b.width && a.height == b.height && a.channels == b.channels &&
         std::memcmp(a.pixels.data(), b.pixels.data(), a.pixels.size() * sizeof(float)) == 0;
}

// Where a difference image of one colour all over is kept ("" when it is not one colour):
// a render that matches its reference has one, and 57 of the solutions' 64 checks share it.
fs::path uniform_image_path(const Run& run, const Image& image) {
  if (run.reference_cache.empty() || image.pixels.empty() || !is_uniform(image)) return {};
  const size_t n = static_cast<size_t>(image.channels);
  std::string name = "uniform-" + std::to_string(image.width) + "x" + std::to_string(image.height);
  for (size_t c = 0; c < n; ++c) {
    uint32_t bits = 0;
    std::memcpy(&bits, &image.pixels[c], sizeof bits);
    char hex[10];
    std::snprintf(hex, sizeof hex, "-%08x", bits);
    name += hex;
  }
  return run.reference_cache / (name + ".png");
}

// The cached report PNG of `check`'s reference; "" where the reference is prepared by the
// build (only read) without it.
fs::path reference_png(const LoadedReference& reference, const Check& check) {
  fs::path cached = reference.cache_stem;
  cached += std::string(".") + metric_name(check.metric) + ".png";
  std::error_code ec;
  return reference.prepared && !fs::exists(cached, ec) ? fs::path() : cached;
}

// The report's three images of a check. What looks the same in every report is encoded
// once and linked: each reference, a render equal to its reference value for value (59 of
// the solutions' 64 checks, about a third of those of a submission with one mistake a lab),
// and a difference image of one colour.
void write_report_images(const Run& run, const fs::path& result_dir, const Check& check, const Image& image,
                         const Image& reference, CheckOutcome& c) {
  std::string base = std::string(kImageFolder) + "/lab" + std::to_string(check.lab) + "-" + check.key;
  c.image = base + ".png";
  c.reference = base + ".ref.png";
  c.diff = base + ".diff.png";
  const Metric shown = shown_metric(check);
  const Image& diff = c.comparison.diff;
  if (!link_cached_png(uniform_image_path(run, diff), result_dir / c.diff, [&] { return diff; }))
    write_report_png(result_dir / c.diff, diff);
  auto shown_reference = [&] { return display_image(shown, reference, reference); };
  if (compares_own_renders(check.metric)) {  // its "reference" is the submission's own render
    write_report_png(result_dir / c.image, display_image(shown, image, reference));
    write_report_png(result_dir / c.reference, shown_reference());
    return;
  }
  const fs::path cached = reference_png(run.references.at(check.reference), check);
  const bool linked = link_cached_png(cached, result_dir / c.reference, shown_reference);
  if (!linked) write_report_png(result_dir / c.reference, shown_reference());
  if (!(linked && same_values(image, reference) && link_cached_png(cached, result_dir / c.image, shown_reference)))
    write_report_png(result_dir / c.image, display_image(shown, image, reference));
}

// Loads a lab's references the first time one of its children has rendered: the
// run's first children start at once, and a lab whose shaders do not compile needs none.
// Returns "" or why they could not be read (the same for every submission of the run).
std::string load_references_of(Run& run, int lab) {
  if (run.references_dir.empty()) return "";
  auto [problem, first] = run.reference_problems.try_emplace(lab);
  if (!first) return problem->second;
  try {
    for (auto& [id, reference] : load_lab_references(run.references_dir, lab, run.reference_cache, run.prepared_references))
      run.references.emplace(id, std::move(reference));
  } catch (const Error& e) {
    problem->second = e.what();
    return problem->second;
  }
  for (const Check* check : lab_checks(lab))
    if (!compares_own_renders(check->metric) && !run.backgrounds.count({check->reference, check->metric}))
      run.backgrounds.emplace(std::make_pair(check->reference, check->metric),
                              cached_background(run.references.at(check->reference), check->metric));
  return "";
}

// The catalogue's signatures, read when the first lab is compared rather than while the
// first children wait to start (7 ms of parsing). A file that is not one stops the run,
// as it did when it was read first.
void load_mistakes_once(Run& run) {
  if (run.mistakes_loaded || run.references_dir.empty()) return;
  run.mistakes = load_mistake_signatures(run.references_dir / kMistakeSignaturesFile);
  run.mistakes_loaded = true;
}

// A failed display or HDR check's worst pixel: what the G-buffer held there and what each light
// gave, from the references of the render's scene (nothing where they are not stored or cannot
// be read).
void add_worst_pixel_inputs(const Run& run, CheckOutcome& c) {
  const auto scene = run.scenes.find(find_render(c.check->image).scene);
  if (scene == run.scenes.end() || run.references_dir.empty()) return;
  add_reference_pixel_inputs(c, scene->second, run.pixel_input_references, [&](const std::string& id) {
    return load_describing_reference(run.references_dir, id, run.reference_cache, run.prepared_references);
  });
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
    for (const RenderSpec* spec : lab_renders(lab.lab, run.renders_describing()))
      renders[spec->id] = read_raw_image(raw_image_path(dir, spec->id));
  } catch (const Error& e) {
    lab.status = kCrash;
    lab.message = e.what();
    return;
  }
  if (run.collect) {
    for (auto& [id, image] : renders) (*run.collect)[id] = std::move(image);
    if (run.collect_probes && child.contains("probes") && child["probes"].is_object())
      for (const auto& [id, values] : child["probes"].items()) (*run.collect_probes)[id] = probe_values_from_json(values);
    lab.status = kGraded;
    return;
  }
  lab.probes = probe_outcomes(lab.lab, child, run.probes_reference);
  fs::create_directories(result_dir / kImageFolder);
  lab.status = kGraded;
  for (CheckOutcome& c : lab.checks) {
    const Check& check = *c.check;
    const bool own = compares_own_renders(check.metric);  // its "reference" is the submission's own render
    const LoadedReference* stored = own ? nullptr : &run.references.at(check.reference);
    StoredReference reference;
    if (stored) {
      reference.image = &stored->image;
      reference.allowance = &stored->allowance;
      if (check.metric != Metric::Work) reference.background = &run.backgrounds.at({check.reference, check.metric});
    }
    compare_check(run.config, lab, c, renders, child, reference);
    if (!c.passed && lab.lab >= 2) add_worst_pixel_inputs(run, c);
    write_report_images(run, result_dir, check, renders.at(check.image),
                        own ? renders.at(check.reference) : stored->image, c);
    c.comparison.diff = Image();  // written: a batch keeps no images in memory
  }
  // A failed check: which catalogued mistake do the lab's signatures resemble?
  name_likely_mistakes(run.mistakes, lab);
  lab.compare_seconds = seconds_since(t0);
}

// kit-grade's caches: $XDG_CACHE_HOME (else ~/.cache) /kit-grade. "" when there is
// no home to put them in. Only this process writes there, never a render child.
fs::path grader_cache_dir() {
  const char* xdg = std::getenv("XDG_CACHE_HOME");
  const char* home = std::getenv("HOME");
  fs::path base = xdg && *xdg ? fs::path(xdg) : home && *home ? fs::path(home) / ".cache" : fs::path();
  return base.empty() ? base : base / "kit-grade";
}

// Mesa's shader cache as the kit's own renders leave it (solutions/ and
// shaders/ only, never a submission's file).
fs::path shader_cache_seed() {
  fs::path cache = grader_cache_dir();
  return cache.empty() ? cache : cache / "mesa-shader-cache";
}

// The decoded references (load_lab_references), their backgrounds and display images:
// kept between runs where the cache can be made, else in the run's temporary folder.
fs::path reference_cache_dir(const fs::path& run_temp) {
  const fs::path cache = grader_cache_dir();
  if (!cache.empty()) {
    std::error_code ec;
    fs::create_directories(cache / "references", ec);
    if (!ec && access((cache / "references").c_str(), W_OK) == 0) return cache / "references";
  }
  fs::create_directories(run_temp / "references");
  return run_temp / "references";
}

// The render children's cache is Mesa's single-file one (a Fossilize database, its
// index and Mesa's size index: 6 files and folders) rather than its default of one file
// per program in a folder per key byte (120 for the seed): every submission's private
// cache starts as a copy of the seed, and on ext4 creating a file cost more than copying
// its bytes (finding a free inode among those the run's temporary files had just freed
// was a fifth of the grading process's CPU profile). Mesa 21.1 and later read it.
constexpr const char* kSingleFileCacheVariable = "MESA_DISK_CACHE_SINGLE_FILE";
// llvmpipe's option that skips LLVM's IR optimisation passes (GALLIVM_PERF=nopt, in Mesa
// 22.3 and 25.0 alike): a render child compiles each program once and draws a few frames of
// 256x192 with it, so the passes cost more than they save. With a cold shader cache a
// submission takes 2.86 s instead of 3.72 s on 2 cores; with the seed it is as fast (the
// seed is compiled the same way: the flags are part of Mesa's cache key). The solutions'
// 62 renders are byte-identical with and without it (docs/performance.md, Grading).
constexpr const char* kFastCompileFlag = "nopt";
// The folder Mesa's default (multi-file) cache keeps its files in.
constexpr const char* kMultiFileCacheFolder = "mesa_shader_cache";


// A submission's private shader cache, in its temporary folder.
fs::path private_shader_cache(const Entry& e) { return e.temp / "mesa-shader-cache"; }

void prepare(const Run& run, Entry& e) {
  e.started = Clock::now();
  e.temp = make_temp_dir(run.temp, "submission-");
  // Started as a copy of the seed, so the programs every submission shares (the
  // earlier labs' solutions, the framework's passes) are not compiled again.
  fs::path seed = shader_cache_seed();
  std::error_code ec;
  if (!run.writes_cache_seed && !seed.empty() && fs::is_directory(seed, ec))
    fs::copy(seed, private_shader_cache(e), fs::copy_options::recursive | fs::copy_options::skip_symlinks, ec);
  e.prepared = prepare_submission(e.source, run.options.labs, e.temp, run.options.limits);
  e.outcome.name = e.prepared->name;
  e.outcome.source = e.source;
  e.outcome.problem = e.prepared->problem;
  e.outcome.notes = e.prepared->notes;
  e.outcome.gpu = run.options.device == Device::Any;
  e.outcome.content_hash = e.content_hash;
}

// A render worker works in each lab's task folder, and Mesa's shader cache (which it
// writes) is the submission's own, in its temporary folder: nothing a student's
// shaders compile to is shared with another student's children or left in
// ~/.cache, and the labs of one submission (and the second scene of a lab) still
// find their compiled shaders. Only runs that render the kit's own files alone
// write the seed.
ChildSetup render_setup(const Run& run, const Entry& e, const fs::path& dir) {
  ChildSetup setup;
  setup.working_dir = dir;
  fs::path seed = shader_cache_seed();
  fs::path cache = run.writes_cache_seed && !seed.empty() ? seed : private_shader_cache(e);
  setup.environment = {{"MESA_SHADER_CACHE_DIR", cache.string()},
                       {kSingleFileCacheVariable, "1"},
                       {"XDG_CACHE_HOME", (e.temp / "cache").string()}};
  // GALLIVM_PERF keeps what the run (a filter rendering) or the caller asked for, plus nopt.
  const char* inherited = std::getenv("GALLIVM_PERF");
  std::string perf = inherited ? inherited : "";
  for (const auto& [name, value] : run.child_environment)
    if (name == "GALLIVM_PERF") perf = value;
    else setup.environment.emplace_back(name, value);
  setup.environment.emplace_back("GALLIVM_PERF", perf.empty() ? kFastCompileFlag : perf + "," + kFastCompileFlag);
  return setup;
}

// Removes the temporary folders of kit-grade runs that ended without removing
// them (kill -9, a power cut): folders "kit-grade-<pid>-XXXXXX" in `base`, owned
// by this user, whose process no longer exists. A folder whose process id is in
// use again is left (harmless; a later run removes it). Says what it removed.
void remove_stale_run_temps(const fs::path& base) {
  std::error_code ec;
  std::vector<std::string> removed;
  for (fs::directory_iterator it(base, ec), end; !ec && it != end; it.increment(ec)) {
    std::string name = it->path().filename().string();
    if (name.rfind(kRunTempPrefix, 0) != 0) continue;
    size_t digits = std::strlen(kRunTempPrefix), dash = name.find('-', digits);
    if (dash == std::string::npos || dash == digits || dash + 7 != name.size()) continue;
    std::string number = name.substr(digits, dash - digits);
    if (number.find_first_not_of("0123456789") != std::string::npos || number.size() > 9) continue;
    pid_t pid = static_cast<pid_t>(std::stol(number));
    struct stat st {};
    if (lstat(it->path().c_str(), &st) != 0 || !S_ISDIR(st.st_mode) || st.st_uid != getuid()) continue;
    if (pid == getpid() || kill(pid, 0) == 0 || errno == EPERM) continue;  // its run is alive
    std::error_code remove_ec;
    fs::remove_all(it->path(), remove_ec);
    if (!remove_ec) removed.push_back(it->path().string() + " (pid " + number + ")");
  }
  if (removed.empty()) return;
  std::string list;
  for (const std::string& r : removed) list += (list.empty() ? "" : ", ") + r;
  std::fprintf(stderr, "kit-grade: removed %zu temporary folder%s left by kit-grade runs that ended without removing them: %s\n",
               removed.size(), removed.size() == 1 ? "" : "s", list.c_str());
}

void print_submission(const SubmissionOutcome& s) {
  if (!s.problem.empty()) std::printf("%s: %s\n", s.name.c_str(), s.problem.c_str());
  for (const auto& [number, lab] : s.labs) std::printf("%s\n", lab_line(lab).c_str());
  std::printf("total: %s/%s\n", format_points(s.total()).c_str(), format_points(s.max_total()).c_str());
  std::fflush(stdout);
}

}  // namespace

// A run that renders only the kit's own files has its children write the seed
// (Mesa creates only the last folder of its cache's path). A multi-file cache an
// older kit-grade left there is removed: no child reads it, and every submission
// would copy it.
void write_cache_seed(Run& run) {
  fs::path seed = shader_cache_seed();
  std::error_code ec;
  if (!seed.empty()) fs::create_directories(seed, ec);
  run.writes_cache_seed = !seed.empty() && !ec;
  if (run.writes_cache_seed) fs::remove_all(seed / kMultiFileCacheFolder, ec);
}

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
  InterruptGuard interrupts;
  const std::vector<int> order = lab_start_order(run.options.labs, run.options.jobs);
  std::deque<Task> queue;
  for (size_t i = 0; i < entries.size(); ++i) {
    entries[i].labs_left = run.options.labs.size();
    for (int lab : order) queue.push_back({i, lab});
  }
  const size_t slots = static_cast<size_t>(std::max(1, run.options.jobs));
  std::vector<Worker> workers;
  auto complete = [&](Entry& e, LabOutcome lab) {
    lab.folder = e.prepared->labs.at(lab.lab).folder;
    e.outcome.labs[lab.lab] = std::move(lab);
    if (--e.labs_left > 0) return;
    e.outcome.seconds = seconds_since(e.started);
    finished(e);
    e.outcome = SubmissionOutcome();  // reported: free it before the next submission
    e.prepared.reset();
    if (!run.options.keep_temp) {
      std::error_code ec;
      fs::remove_all(e.temp, ec);
    }
  };
  // Labs at the front of the queue whose files could not be prepared are complete at once.
  auto skip_unready = [&] {
    while (!queue.empty()) {
      Entry& e = entries[queue.front().entry];
      if (!e.prepared) prepare(run, e);
      const LabFiles& files = e.prepared->labs.at(queue.front().lab);
      if (files.ready) return;
      LabOutcome lab = empty_lab(run, queue.front().lab);
      lab.status = files.status;
      lab.message = trimmed(files.message);
      queue.pop_front();
      complete(e, std::move(lab));
    }
  };
  // The next lab of the worker's submission, or stop when there is none it may take.
  auto give_lab = [&](Worker& w) {
    skip_unready();
    if (!queue.empty() && queue.front().entry == w.entry && !(queue.front().alone && w.labs_done > 0)) {
      w.lab = queue.front().lab;
      queue.pop_front();
      fs::create_directories(lab_folder(entries[w.entry].temp, w.lab));
      w.child->send_task(w.lab);  // a worker already gone ends the lab: poll() says how
      return;
    }
    w.child->send_task(0);
    w.lab = 0;
  };
  auto start_workers = [&] {
    for (skip_unready(); workers.size() < slots && !queue.empty(); skip_unready()) {
      Entry& e = entries[queue.front().entry];
      const LabWorker spec{e.prepared->lab_root, e.temp, run.options.backend, run.options.device, &run.scenes,
                           &run.probes_reference, run.renders_describing()};
      Worker w;
      w.entry = queue.front().entry;
      w.child = std::make_unique<Child>(Child::fork_worker(
          [spec](TaskChannel& channel) { return serve_labs(spec, channel); }, run.options.limits,
          static_cast<int>(run.options.labs.size()), e.temp / "worker.log", render_setup(run, e, e.temp)));
      give_lab(w);
      workers.push_back(std::move(w));
    }
  };
  std::vector<Rendered> rendered;
  // The lab `w` renders ended as `o`: compared, or rendered again alone when the worker
  // ended abnormally (`verdict`: the lab's own status, reported) after another lab.
  auto lab_ended = [&](const Worker& w, const Outcome& o, bool verdict) {
    if (!verdict && render_again_alone(o, w.labs_done))
      queue.push_front({w.entry, w.lab, true});
    else
      rendered.push_back({{w.entry, w.lab}, o});
  };
  while (!queue.empty() || !workers.empty()) {
    if (int sig = interrupts.pending()) {
      std::fprintf(stderr, "kit-grade: %s: stopping the renderers\n", strsignal(sig));
      workers.clear();  // each Child kills its process group
      return false;
    }
    start_workers();
    for (size_t i = 0; i < workers.size();) {
      Worker& w = workers[i];
      const bool ended = w.child->poll();  // a report sent before the worker ended is read below
      while (const std::optional<Child::TaskResult> report = w.child->next_report()) {
        if (report->task != w.lab) continue;
        const Outcome& o = report->outcome;
        lab_ended(w, o, o.kind == Outcome::Kind::Exited);
        w.lab = 0;
        ++w.labs_done;
        // The next lab renders while this one is compared; after a lab that did not
        // render, the worker ends and the next lab gets a fresh one.
        if (!ended && o.kind == Outcome::Kind::Exited && o.code == kChildOk) give_lab(w);
      }
      if (!ended) {
        ++i;
        continue;
      }
      if (w.lab != 0) lab_ended(w, w.child->outcome(), false);  // it ended during a lab
      workers.erase(workers.begin() + static_cast<std::ptrdiff_t>(i));
    }
    if (rendered.empty()) {
      poll_pause();
      continue;
    }
    // The next labs render while this process compares the finished ones.
    start_workers();
    for (Rendered& done : rendered) {
      Entry& e = entries[done.task.entry];
      const fs::path dir = lab_folder(e.temp, done.task.lab);
      LabOutcome lab = empty_lab(run, done.task.lab);
      const Outcome& o = done.outcome;
      lab.child_seconds = o.wall_seconds;
      lab.child_cpu_seconds = o.cpu_seconds;
      lab.child_max_rss_kib = o.max_rss_kib;
      if (classify_child(o, dir, lab)) {
        load_mistakes_once(run);
        const std::string problem = load_references_of(run, lab.lab);
        if (problem.empty()) {
          compare_lab(run, dir, e.result_dir, lab);
        } else {
          lab.status = kGraderError;
          lab.message = "the grader could not read this lab's references: " + problem;
        }
      }
      std::ifstream child_report(dir / "child.json");
      if (child_report) {
        try {
          e.outcome.renderer = nlohmann::json::parse(child_report).value("renderer", "");
          e.outcome.references_renderer = run.references_renderer;
          e.outcome.measured_on = run.config.measured_on_text();
          e.outcome.within_measured = run.config.measured_on_renderer(e.outcome.renderer);
        } catch (const nlohmann::json::exception&) {
        }
      }
      // A graded lab whose custom effect was rendered on the submission's own bloom.
      const auto renders = lab_renders(done.task.lab);
      if (lab.status == kGraded && !custom_effect_isolated(find_stage(done.task.lab)) &&
          std::any_of(renders.begin(), renders.end(), [](const RenderSpec* r) { return r->isolate_custom; }))
        e.outcome.notes.push_back("lab " + std::to_string(done.task.lab) + ": " + kOwnBloomNote);
      complete(e, std::move(lab));
    }
    rendered.clear();
  }
  return true;
}

Run make_run(const Options& options, bool need_references) {
  Run run{options, load_config(options.config.empty() ? default_config_path() : options.config), {}, {}, {}, {}, {}, nullptr, {}, false, {}, {}, {}, {}, false, {}, {}, {}, nullptr};
  if (need_references) {
    run.references_dir = options.references.empty() ? default_references_dir() : options.references;
    require_current_references(run.references_dir);
    run.references_renderer = references_renderer(run.references_dir);
    run.probes_reference = read_probes_reference(run.references_dir);
  }
  // A run that makes the references (none needed) renders those that describe a pixel too.
  run.scenes = load_scenes(options.labs, !need_references);
  const char* tmp = std::getenv("TMPDIR");
  fs::path base = fs::absolute(tmp && *tmp ? tmp : "/tmp");
  remove_stale_run_temps(base);
  // Named with this process's id, so a later run can tell when it is gone.
  run.temp = make_temp_dir(base, kRunTempPrefix + std::to_string(getpid()) + "-");
  if (need_references) {
    run.reference_cache = reference_cache_dir(run.temp);
    run.prepared_references = prepared_references_dir();
  }
  return run;
}

void remove_run_temp(const Run& run) {
  if (run.options.keep_temp) {
    // Renamed out of kRunTempPrefix's pattern, or the next run would remove it as stale.
    const std::string name = run.temp.filename().string();
    fs::path kept = run.temp.parent_path() / (kKeptTempPrefix + name.substr(std::strlen(kRunTempPrefix)));
    std::error_code ec;
    fs::rename(run.temp, kept, ec);
    std::fprintf(stderr, "kit-grade: temporary files kept in %s\n", (ec ? run.temp : kept).c_str());
    return;
  }
  std::error_code ec;
  fs::remove_all(run.temp, ec);
}

int grade_submission(const fs::path& submission, const Options& options) {
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
    std::fprintf(stderr, "kit-grade: the grader could not grade every lab (see %s)\n", (options.out / "summary.json").c_str());
    return 2;
  }
  return 0;
}

int prepare_references(const Options& options, const fs::path& out) {
  const fs::path dir = options.references.empty() ? default_references_dir() : options.references;
  try {
    require_current_references(dir);
    fs::create_directories(out);
    for (int lab : options.labs) {
      // Made as a grading run's cache holds them: the same names and bytes (no prepared folder to read).
      const std::map<std::string, LoadedReference> references = load_lab_references(dir, lab, out);
      for (const Check* check : lab_checks(lab)) {
        if (compares_own_renders(check->metric)) continue;
        const LoadedReference& reference = references.at(check->reference);
        cached_background(reference, check->metric);
        cache_png(reference_png(reference, *check),
                  [&] { return display_image(shown_metric(*check), reference.image, reference.image); });
      }
      // And those a failed check's worst pixel is described from (made at their own stage).
      for (const RenderSpec* spec : lab_renders(lab, true))
        if (spec->describes_pixels_only) load_describing_reference(dir, spec->id, out);
    }
  } catch (const std::exception& e) {  // grading makes them in its cache instead
    std::fprintf(stderr, "kit-grade: the references were not prepared in %s: %s\n", out.c_str(), e.what());
  }
  return 0;
}

}  // namespace kit::grade
