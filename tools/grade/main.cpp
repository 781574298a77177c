// kit-grade: the autograder. handouts/instructors.md explains every flag, the
// checks, the tolerances and the output files.
//
//   kit-grade SUBMISSION [--labs 1-7] [--out DIR] [--jobs N] [--backend osmesa|egl]
//   kit-grade --batch FOLDER --out DIR [--jobs N] [--force]   (regrades what changed since its result)
//   kit-grade --update-references | --check-references
//   kit-grade --prepare-references DIR   (run by the build: tools/grade.cmake)
//
// Exit status: 0 when grading ran (whatever the score), 1 when --check-references
// finds stale references, 2 when the grader itself could not run.
#include <nlohmann/json.hpp>

#include <unistd.h>

#include <cstdio>
#include <cstring>
#include <thread>

#include "base/error.h"
#include "base/hugepage_malloc.h"
#include "batch/batch.h"
#include "gl/context.h"
#include "intake/submission.h"
#include "render/stages.h"
#include "run/grader.h"
#include "run/reference_maintenance.h"

namespace fs = std::filesystem;

namespace {

// Default --jobs: labs rendered at once. Two render workers keep two cores busy
// (a lab's compile and read-back are single-threaded); more only adds memory.
constexpr int kMaxDefaultJobs = 2;

void usage() {
  std::printf(
      "usage: kit-grade SUBMISSION [--labs 1-7] [--out DIR] [options]\n"
      "       kit-grade --batch FOLDER --out DIR [--force] [options]\n"
      "       kit-grade --update-references | --check-references | --prepare-references DIR [--references DIR]\n"
      "       kit-grade --self-check [self_check.py options]\n"
      "       kit-grade --name-again RESULT... [--references DIR]\n"
      "Grades a student's lab files against the reference solutions. SUBMISSION is a folder or a .zip holding\n"
      "the lab folders (NN-name/file, any case) at most %zu folders deep: 02-lighting/, labs/02-lighting/,\n"
      "alice/labs/02-lighting/ or alice/alice/labs/02-lighting/. With one lab graded (--labs 2) its files may\n"
      "also lie loose, at the top or inside one folder. A lab folder found in two places is refused, naming both.\n"
      "Writes DIR/results.json (Gradescope), DIR/summary.json, DIR/report.html; their notes say which folder\n"
      "each lab was taken from. Only regular files with one name are read (symbolic and hard links are refused);\n"
      "a zip is refused whole when an entry would leave its folder or it lists over %zu entries, and an\n"
      "encrypted or damaged (bad CRC) lab file in it is refused by name.\n"
      "  --labs SPEC           labs to grade (default: every lab this kit can grade), 1-3, 2, 1,3,5 or names (lighting)\n"
      "  --out DIR             result folder (default out/grade/<submission name>)\n"
      "  --jobs N              labs (and batch submissions) rendered at once (default: cores, at most %d)\n"
      "  --backend NAME        osmesa | egl (default: osmesa where this build has it, else egl)\n"
      "  --gpu                 render with whatever device the platform gives first (a GPU), not Mesa's software\n"
      "                        rasteriser (the default: the implementations the tolerances were measured on);\n"
      "                        the report then says the verdict comes from the GPU\n"
      "  --cpu-limit S         the time limit: CPU seconds a lab's renderer may use, all its threads together\n"
      "                        (RLIMIT_CPU, default %lu); CPU time does not grow when the machine is busy\n"
      "  --timeout S           wall-clock backstop per lab (default %.0f): a renderer still running after S s is\n"
      "                        stopped whatever CPU it used (keep it well above --cpu-limit)\n"
      "  --memory-limit MIB    address space of a lab's renderer (RLIMIT_AS, default 4096); one that runs out\n"
      "                        is reported as \"out of memory (limit MIB MiB)\" (status crash)\n"
      "  --config FILE         weights, points and tolerances (default tools/grade/grading.json)\n"
      "  --references DIR      reference renders (default tools/grade/references)\n"
      "  --batch FOLDER        grade every subfolder and .zip of FOLDER into DIR/<name>/, plus DIR/gradebook.csv;\n"
      "                        a submission with a results.json is skipped unless its files changed since\n"
      "                        (content hash in its summary.json) or --force. A submission named like the\n"
      "                        batch's own files (gradebook.csv, results.json, summary.json, report.html, img)\n"
      "                        gets DIR/<name>.submission/. One batch at a time per DIR: a second is refused\n"
      "                        (exit 2) while the first holds DIR/.kit-grade.lock\n"
      "  --keep-temp           keep the sanitized copies and raw renders (path printed)\n"
      "  --update-references   render solutions/ into the references and write their manifest\n"
      "  --check-references    re-render solutions/ and fail (exit 1) when the references are stale\n"
      "  --prepare-references DIR  decode the references into DIR with their backgrounds and report images\n"
      "                        (the build does, beside kit-grade; runs read them there)\n"
      "  --self-check          run instructor/grading/self_check.py (the mistake catalogue) with this grader\n"
      "  --name-again RESULT...  name the likely mistakes of the result folders' failed labs again from their\n"
      "                        naming.json and the references' mistakes.json as it is now, without rendering;\n"
      "                        prints {RESULT: {LAB: [mistakes as summary.json lists them]}} as JSON\n"
      "Labs render in worker processes, --jobs at once, each taking a submission's labs one after another under each\n"
      "lab's own limits, in the run's temporary folder ($TMPDIR/kit-grade-<pid>-XXXXXX, removed\n"
      "at the end; a later run removes those of runs that were killed) with a Mesa shader cache of its submission's\n"
      "own there (a copy of the seed --check-references writes from the solutions in\n"
      "$XDG_CACHE_HOME/kit-grade/mesa-shader-cache), and at most %lu open files and (not as root) %lu more\n"
      "processes than its user has.\n",
      kit::grade::kMaxWrapperDepth, kit::grade::kMaxZipEntries, kMaxDefaultJobs, static_cast<unsigned long>(kit::grade::kDefaultCpuSeconds),
      kit::grade::kDefaultWallSeconds, static_cast<unsigned long>(kit::grade::Limits{}.open_files),
      static_cast<unsigned long>(kit::grade::Limits{}.extra_processes));
}

int parse_int(const std::string& text, const std::string& flag, int lo, int hi) {
  try {
    size_t used = 0;
    int v = std::stoi(text, &used);
    if (used == text.size() && v >= lo && v <= hi) return v;
  } catch (const std::exception&) {
  }
  throw kit::Error(flag + " expects a whole number from " + std::to_string(lo) + " to " + std::to_string(hi) +
                   " (got '" + text + "')");
}

// "1-6", "2", "1,3,5", "lighting,5" -> lab numbers, ascending, each once.
std::vector<int> parse_labs(const std::string& spec) {
  std::vector<bool> chosen(kit::stages().size() + 1, false);
  size_t start = 0;
  while (start <= spec.size()) {
    size_t comma = spec.find(',', start);
    std::string part = spec.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    size_t dash = part.find('-');
    bool single = true;  // "02-lighting" is one lab; "2-4" a range
    try {
      kit::find_stage(part);
    } catch (const kit::Error&) {
      single = false;
    }
    if (!single && dash != std::string::npos && dash > 0) {
      int a = kit::find_stage(part.substr(0, dash)).number, b = kit::find_stage(part.substr(dash + 1)).number;
      if (a > b) throw kit::Error("--labs: range '" + part + "' runs backwards");
      for (int i = a; i <= b; ++i) chosen[static_cast<size_t>(i)] = true;
    } else {
      chosen[static_cast<size_t>(kit::find_stage(part).number)] = true;
    }
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  std::vector<int> labs;
  for (size_t i = 1; i < chosen.size(); ++i)
    if (chosen[i]) labs.push_back(static_cast<int>(i));
  return labs;
}

fs::path self_path(const char* argv0) {
  std::error_code ec;
  fs::path p = fs::read_symlink("/proc/self/exe", ec);
  return ec ? fs::absolute(argv0) : p;
}

// --self-check: the catalogue's runner, told to use this very binary.
int self_check(int argc, char** argv, int first) {
  fs::path script_path = kit::kit_root() / "instructor" / "grading" / "self_check.py";
  if (!fs::exists(script_path)) {
    std::fprintf(stderr, "kit-grade: --self-check needs the mistake catalogue (%s), which only the instructor's kit has\n",
                 script_path.c_str());
    return 2;
  }
  std::string script = script_path.string();
  std::string me = self_path(argv[0]).string();
  std::vector<std::string> args = {"python3", script, "--kit-grade", me};
  for (int i = first; i < argc; ++i) args.push_back(argv[i]);
  std::vector<char*> raw;
  for (std::string& a : args) raw.push_back(a.data());
  raw.push_back(nullptr);
  execvp(raw[0], raw.data());
  std::fprintf(stderr, "kit-grade: cannot run %s with python3: %s\n", script.c_str(), std::strerror(errno));
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  // Huge pages for every buffer of this process and its render workers: each lab's targets,
  // images and llvmpipe's zeroed textures fault in 2 MiB at a time. Grading the solutions
  // warm on 2 cores took 0.80 s instead of 1.14 (docs/performance.md, Grading); starting
  // twice costs about 15 ms. Where exec fails, grading goes on without.
  if (kit::request_hugepage_malloc()) execv("/proc/self/exe", argv);
  kit::keep_freed_memory_for_reuse();
  kit::grade::Options options;
  options.jobs = std::max(1, std::min(kMaxDefaultJobs, static_cast<int>(std::thread::hardware_concurrency())));
  std::string batch;
  std::vector<std::string> positional;  // the SUBMISSION, or --name-again's RESULT folders
  enum class Mode { Grade, Batch, Update, Check, Prepare, NameAgain } mode = Mode::Grade;
  fs::path prepared;
  const int status = kit::run_tool("kit-grade", 2, [&]() -> int {
    for (int i = 1; i < argc; ++i) {
      std::string flag = argv[i];
      auto value = [&]() -> std::string {
        if (i + 1 >= argc) throw kit::Error(flag + " needs a value");
        return argv[++i];
      };
      if (flag == "--help" || flag == "-h") {
        usage();
        return 0;
      } else if (flag == "--self-check") {
        return self_check(argc, argv, i + 1);
      } else if (flag == "--labs") {
        options.labs = parse_labs(value());
      } else if (flag == "--out") {
        options.out = value();
      } else if (flag == "--jobs" || flag == "-j") {
        options.jobs = parse_int(value(), flag, 1, 64);
      } else if (flag == "--backend") {
        options.backend = kit::parse_backend(value());
        if (options.backend == kit::Backend::Window) throw kit::Error("--backend: grading is headless (osmesa or egl)");
      } else if (flag == "--timeout") {
        options.limits.wall_seconds = parse_int(value(), flag, 1, 3600);
      } else if (flag == "--cpu-limit") {
        options.limits.cpu_seconds = static_cast<rlim_t>(parse_int(value(), flag, 1, 3600));
      } else if (flag == "--memory-limit") {
        options.limits.address_space_mib = static_cast<rlim_t>(parse_int(value(), flag, 256, 1 << 20));
      } else if (flag == "--config") {
        options.config = value();
      } else if (flag == "--references") {
        options.references = value();
      } else if (flag == "--batch") {
        batch = value();
        mode = Mode::Batch;
      } else if (flag == "--gpu") {
        options.device = kit::Device::Any;
      } else if (flag == "--force") {
        options.force = true;
      } else if (flag == "--keep-temp") {
        options.keep_temp = true;
      } else if (flag == "--update-references") {
        mode = Mode::Update;
      } else if (flag == "--check-references") {
        mode = Mode::Check;
      } else if (flag == "--prepare-references") {
        prepared = value();
        mode = Mode::Prepare;
      } else if (flag == "--name-again") {
        mode = Mode::NameAgain;
      } else if (!flag.empty() && flag[0] == '-') {
        throw kit::Error("unknown option '" + flag + "' (see --help)");
      } else {
        positional.push_back(flag);
      }
    }
    if (mode == Mode::NameAgain) {
      if (positional.empty()) throw kit::Error("--name-again needs one or more result folders");
      return kit::grade::name_again({positional.begin(), positional.end()}, options);
    }
    if (positional.size() > 1)
      throw kit::Error("one SUBMISSION at a time ('" + positional[0] + "' and '" + positional[1] +
                       "'); use --batch FOLDER for more");
    const std::string submission = positional.empty() ? "" : positional[0];
    // The renderer's library opens beside the run's setup (scenes, submission), before the
    // first render worker is forked.
    if (mode != Mode::Prepare) kit::preload_headless_library(options.backend);
    // Default: every lab this kit can grade (all in the instructor's kit; a student
    // copy's own lab). A lab named with --labs whose earlier solutions are missing
    // is refused here, with what is missing, rather than failing in every submission.
    if (options.labs.empty()) options.labs = kit::gradable_labs();
    if (mode == Mode::Grade || mode == Mode::Batch)
      for (int lab : options.labs) kit::require_earlier_solutions(kit::find_stage(lab));
    switch (mode) {
      case Mode::Update: return kit::grade::update_references(options);
      case Mode::Check: return kit::grade::check_references(options);
      case Mode::Prepare: return kit::grade::prepare_references(options, prepared);
      case Mode::NameAgain: break;  // answered above, before the renderer's library opens
      case Mode::Batch:
        if (!submission.empty()) throw kit::Error("--batch grades a folder of submissions: no SUBMISSION as well");
        if (options.out.empty()) throw kit::Error("--batch needs --out DIR");
        options.quiet = true;
        return kit::grade::grade_batch(batch, options);
      case Mode::Grade:
        if (submission.empty()) throw kit::Error("no SUBMISSION given (see --help)");
        if (options.out.empty()) options.out = fs::path("out") / "grade" / kit::grade::submission_name(submission);
        return kit::grade::grade_submission(submission, options);
    }
    return 0;
  });
  // Before exit runs the destructors of static objects: the library may still be opening
  // on its thread (a run that forks no child), constructing statics that exit would destroy.
  kit::finish_preloading();
  return status;
}
