#include "worker/render_worker.h"

#include <nlohmann/json.hpp>

#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <memory>

#include "base/error.h"
#include "base/freed_memory.h"
#include "files/files.h"
#include "frames/checks.h"
#include "frames/lab_frames.h"
#include "frames/probe_pass.h"
#include "gl/gl.h"
#include "gl/pass_clock.h"
#include "intake/sandbox.h"
#include "render/renderer.h"
#include "render/stages.h"

namespace fs = std::filesystem;

namespace kit::grade {

namespace {

using Clock = std::chrono::steady_clock;

struct RenderJob {
  int lab = 0;
  const RenderWorker* worker = nullptr;
  fs::path out_dir;  // where the lab writes its files
};

// One lab, with the worker's context (made by its first lab).
int render_lab(const RenderJob& job, std::unique_ptr<GlContext>& context) {
  const fs::path error_file = job.out_dir / "error.txt";
  const Stage& stage = find_stage(job.lab);
  nlohmann::json report;
  auto t0 = Clock::now();
  try {
    if (!context) context = create_headless_context(job.worker->backend, job.worker->device);
  } catch (const Error& e) {
    write_text(error_file, e.what());
    return kWorkerEnvironmentError;
  }
  report["renderer"] = context->describe();
  report["seconds"]["context"] = seconds_since(t0);

  LabFrames frames(stage, job.worker->lab_root, *job.worker->scenes);
  double compile = 0.0, render = 0.0, readback = 0.0;
  for (const RenderSpec* spec : lab_renders(job.lab, job.worker->describing_renders)) {
    // Timings per Renderer (instructor/grading/measure.sh breaks a lab down by them).
    const std::string renderer_name = LabFrames::renderer_name(*spec);
    report["renderer_of"][spec->id] = renderer_name;
    Renderer* renderer = nullptr;
    try {
      double seconds = 0.0;
      renderer = &frames.renderer_for(*spec, &seconds);
      if (seconds > 0.0) {
        compile += seconds;
        report["seconds"]["compile_each"][renderer_name] = seconds;
      }
    } catch (const NonFiniteMapError& e) {
      write_text(error_file, e.what());
      return kWorkerMapError;
    } catch (const Error& e) {
      write_text(error_file, e.what());
      return job.worker->scenes->count(spec->scene) ? kWorkerShaderError : kWorkerEnvironmentError;
    }
    try {
      if (spec->light_shares) {  // describing only: no check reads it, nothing counted
        write_raw_image(raw_image_path(job.out_dir, spec->id), frames.light_shares(*spec));
        continue;
      }
      if (const double seconds = frames.draw(*spec); seconds > 0.0) {
        render += seconds;
        report["seconds"]["render_each"][spec->id] = seconds;
      }
      if (stage.light_volumes)  // the frame's counted work, for lab 7's work checks
        report["work"][spec->id] = work_json(renderer->light_volume_work(), renderer->light_volume_state());
      auto t = Clock::now();
      write_raw_image(raw_image_path(job.out_dir, spec->id), renderer->read_view(spec->view, spec->raw));
      // A display image cannot hold NaN (RGBA8): count them where they start, in the HDR
      // buffer. Stage 6's maps are float images made before the frame: they count their own.
      if (stage.lighting && spec->view != View::Hdr && !is_precomputed_map(spec->view))
        report["hdr_non_finite"][spec->id] = renderer->count_non_finite(View::Hdr);
      readback += seconds_since(t);
    } catch (const NonFiniteMapError& e) {  // the maps of another environment, made for this render
      write_text(error_file, e.what());
      return kWorkerMapError;
    } catch (const Error& e) {
      write_text(error_file, std::string("while rendering ") + spec->scene + ": " + e.what());
      return kWorkerRenderError;
    }
  }
  // The lab's function probes (probe_pass.h), with the context the renders used.
  if (!function_probes(job.lab).empty()) {
    auto t = Clock::now();
    report_function_probes(stage, job.worker->lab_root,
                           job.worker->probes_reference ? *job.worker->probes_reference : nlohmann::json(), report);
    report["seconds"]["probes"] = seconds_since(t);
  }
  report["programs_reused"] = frames.programs_reused();
  report["seconds"]["compile"] = compile;
  report["seconds"]["render"] = render;
  report["seconds"]["readback"] = readback;
  report["seconds"]["total"] = seconds_since(t0);
  report["vm_peak_kib"] = peak_address_space_kib();  // what RLIMIT_AS limits
  write_text(job.out_dir / "child.json", json_text(report));
  return kWorkerOk;
}

}  // namespace

fs::path lab_folder(const fs::path& temp, int lab) { return temp / ("lab" + std::to_string(lab)); }

int RenderWorker::serve(TaskChannel& channel) const {
  keep_freed_memory_between_scenes();  // a lab's scenes, then the next lab's, reuse the pages
  std::unique_ptr<GlContext> context;
  int status = kWorkerOk;
  while (status == kWorkerOk) {
    const int lab = channel.next_task();
    if (lab == 0) break;
    RenderJob job{lab, this, lab_folder(temp, lab)};
    TaskChannel::log_to(job.out_dir / "child.log");
    if (chdir(job.out_dir.c_str()) != 0) {
      std::fprintf(stderr, "kit-grade: child: cannot enter %s: %s\n", job.out_dir.c_str(), std::strerror(errno));
      status = kWorkerEnvironmentError;
    } else {
      status = render_lab(job, context);
    }
    channel.report(lab, status);
  }
  // Destroyed here rather than at _exit: Mesa writes its queued shader-cache entries.
  context.reset();
  return status;
}

}  // namespace kit::grade
