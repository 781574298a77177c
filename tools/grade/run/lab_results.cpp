#include "run/lab_results.h"

#include <nlohmann/json.hpp>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <map>
#include <string>

#include "base/error.h"
#include "files/files.h"
#include "frames/lab_frames.h"
#include "gl/pass_clock.h"
#include "render/stages.h"
#include "verdict/lab_verdict.h"
#include "worker/render_worker.h"

namespace fs = std::filesystem;

namespace kit::grade {

namespace {

// How much of a worker's error file and log the messages quote.
constexpr size_t kErrorBytes = 64 * 1024;
constexpr size_t kLogTailBytes = 2 * 1024;
// Report images live in this folder of a result folder.
constexpr const char* kImageFolder = "img";

// Said in the notes when lab 5's custom effect was rendered on the submission's own bloom
// (lab_frames.cpp, isolated_custom_library): a kit without lab 5's solution.
constexpr const char* kOwnBloomNote =
    "this kit has no reference solution of this lab (a student copy), so the custom effect was graded on your own "
    "bloom; the official grader isolates it on the reference bloom, so a bloom mistake costs points here that it "
    "does not there, and a correct lab gets the same marks in both";

std::string read_text(const fs::path& path) { return read_tail(path, kErrorBytes); }

// Sets status and message from how the worker ended the lab; true when it rendered everything.
bool classify_worker_end(const Outcome& o, const fs::path& dir, LabOutcome& lab) {
  std::string log = trimmed(read_tail(dir / "child.log", kLogTailBytes));
  std::string log_part = log.empty() ? "" : "\n\nlast output of the renderer:\n" + log;
  char buf[320];
  switch (o.kind) {
    case Outcome::Kind::TimedOut:
      // The backstop: the CPU limit ends a shader that loops; this one a worker that
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
  // What the worker wrote of its failure, where it says it failed (read only then).
  const auto error_text = [&dir] { return trimmed(read_text(dir / "error.txt")); };
  switch (o.code) {
    case kWorkerOk: return true;
    case kWorkerShaderError:
      lab.status = kCompileError;
      lab.message = error_text();
      return false;
    case kWorkerEnvironmentError:
      lab.status = kGraderError;
      lab.message = "the grader could not render: " + error_text();
      return false;
    case kWorkerMapError:
      lab.status = kNonFiniteMap;
      lab.message = error_text();
      return false;
    case kWorkerRenderError:
      lab.status = kCrash;
      lab.message = "the frame could not be rendered: " + error_text();
      return false;
    default: break;
  }
  lab.status = kCrash;
  lab.message = "the renderer stopped with " + o.describe() + log_part;
  return false;
}

// cache_png, then `destination` made a link to the cached PNG, or a copy where the result
// folder is on another file system. A linked file costs a fraction of encoding one (a new
// file costs more than its bytes: grading_run.cpp, kSingleFileCacheVariable, says why).
// False when the cache cannot hold it: the caller writes its own file.
bool link_cached_png(const fs::path& cached, const fs::path& destination, const std::function<Image()>& make) {
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

// Loads a lab's references the first time one of its workers has rendered: the
// run's first workers start at once, and a lab whose shaders do not compile needs none.
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
// first workers wait to start (7 ms of parsing). A file that is not one stops the run,
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

// Compares every check of a lab whose worker rendered it.
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

}  // namespace

bool cache_png(const fs::path& cached, const std::function<Image()>& make) {
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

fs::path reference_png(const LoadedReference& reference, const Check& check) {
  fs::path cached = reference.cache_stem;
  cached += std::string(".") + metric_name(check.metric) + ".png";
  std::error_code ec;
  return reference.prepared && !fs::exists(cached, ec) ? fs::path() : cached;
}

LabOutcome empty_lab(const Run& run, int lab) { return lab_outcome(run.config, lab); }

LabOutcome grade_rendered_lab(Run& run, Entry& e, int lab_number, const Outcome& o) {
  const fs::path dir = lab_folder(e.temp, lab_number);
  LabOutcome lab = empty_lab(run, lab_number);
  lab.child_seconds = o.wall_seconds;
  lab.child_cpu_seconds = o.cpu_seconds;
  lab.child_max_rss_kib = o.max_rss_kib;
  if (classify_worker_end(o, dir, lab)) {
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
  const auto renders = lab_renders(lab_number);
  if (lab.status == kGraded && !custom_effect_isolated(find_stage(lab_number)) &&
      std::any_of(renders.begin(), renders.end(), [](const RenderSpec* r) { return r->isolate_custom; }))
    e.outcome.notes.push_back("lab " + std::to_string(lab_number) + ": " + kOwnBloomNote);
  return lab;
}

}  // namespace kit::grade
