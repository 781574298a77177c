#include "run/grading_run.h"

#include <signal.h>
#include <stdlib.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>

#include "base/error.h"
#include "frames/checks.h"

namespace fs = std::filesystem;

namespace kit::grade {

namespace {

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

// kit-grade's caches: $XDG_CACHE_HOME (else ~/.cache) /kit-grade. "" when there is
// no home to put them in. Only this process writes there, never a render worker.
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

// The render workers' cache is Mesa's single-file one (a Fossilize database, its
// index and Mesa's size index: 6 files and folders) rather than its default of one file
// per program in a folder per key byte (120 for the seed): every submission's private
// cache starts as a copy of the seed, and on ext4 creating a file cost more than copying
// its bytes (finding a free inode among those the run's temporary files had just freed
// was a fifth of the grading process's CPU profile). Mesa 21.1 and later read it.
constexpr const char* kSingleFileCacheVariable = "MESA_DISK_CACHE_SINGLE_FILE";
// llvmpipe's option that skips LLVM's IR optimisation passes (GALLIVM_PERF=nopt, in Mesa
// 22.3 and 25.0 alike): a render worker compiles each program once and draws a few frames of
// 256x192 with it, so the passes cost more than they save. With a cold shader cache a
// submission takes 2.86 s instead of 3.72 s on 2 cores; with the seed it is as fast (the
// seed is compiled the same way: the flags are part of Mesa's cache key). The solutions'
// 62 renders are byte-identical with and without it (docs/performance.md, Grading).
constexpr const char* kFastCompileFlag = "nopt";
// The folder Mesa's default (multi-file) cache keeps its files in.
constexpr const char* kMultiFileCacheFolder = "mesa_shader_cache";


// A submission's private shader cache, in its temporary folder.
fs::path private_shader_cache(const Entry& e) { return e.temp / "mesa-shader-cache"; }

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

}  // namespace

void prepare_entry(const Run& run, Entry& e) {
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
// shaders compile to is shared with another student's workers or left in
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

// A run that renders only the kit's own files has its workers write the seed
// (Mesa creates only the last folder of its cache's path). A multi-file cache an
// older kit-grade left there is removed: no worker reads it, and every submission
// would copy it.
void write_cache_seed(Run& run) {
  fs::path seed = shader_cache_seed();
  std::error_code ec;
  if (!seed.empty()) fs::create_directories(seed, ec);
  run.writes_cache_seed = !seed.empty() && !ec;
  if (run.writes_cache_seed) fs::remove_all(seed / kMultiFileCacheFolder, ec);
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

}  // namespace kit::grade
