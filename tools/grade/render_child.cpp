#include "render_child.h"

#include <nlohmann/json.hpp>

#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <memory>

#include "checks.h"
#include "base/error.h"
#include "gl/gl.h"
#include "gl/pass_clock.h"
#include "render/renderer.h"
#include "sandbox.h"
#include "report.h"
#include "render/stages.h"

namespace fs = std::filesystem;

namespace kit::grade {

namespace {

constexpr char kRawMagic[8] = {'K', 'I', 'T', 'R', 'A', 'W', '1', '\0'};
// Larger than any render the grader makes: a corrupt header cannot make the parent allocate gigabytes.
constexpr int kMaxRawDimension = 8192;

using Clock = std::chrono::steady_clock;

void write_text(const fs::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
}

// The library for lab 5's isolated custom effect: the submission's
// custom_effect.frag in front of the solution's stage 5, so the toggle is
// graded whatever the submission's bloom does; where the kit has no such solution
// (custom_effect_isolated), the submission's own stage, which a correct lab gets the
// same marks for.
ShaderLibrary isolated_custom_library(const Stage& stage, const fs::path& lab_root) {
  if (!custom_effect_isolated(stage)) return stage_library(stage, lab_root);
  std::vector<ShaderFolder> folders = stage_library(stage, kit_root() / "solutions").folders();
  ShaderFolder student = stage_library(stage, lab_root).folders().front();
  student.only = {"custom_effect.frag"};
  folders.insert(folders.begin(), student);
  return ShaderLibrary(std::move(folders));
}

// Whether a frame rendered with `a` is the frame `b` would render (the camera is the scene's).
bool same_frame_settings(const RenderSettings& a, const RenderSettings& b) {
  return same_image_settings(a, b) && a.width == b.width && a.height == b.height && a.time == b.time;
}

}  // namespace

bool custom_effect_isolated(const Stage& stage) { return fs::is_directory(kit_root() / "solutions" / stage.folder); }

fs::path raw_image_path(const fs::path& dir, const std::string& render_id) { return dir / (render_id + ".raw"); }

void write_raw_image(const fs::path& path, const Image& image) {
  std::ofstream out(path, std::ios::binary);
  int32_t header[3] = {image.width, image.height, image.channels};
  out.write(kRawMagic, sizeof kRawMagic);
  out.write(reinterpret_cast<const char*>(header), sizeof header);
  out.write(reinterpret_cast<const char*>(image.pixels.data()), static_cast<std::streamsize>(image.pixels.size() * sizeof(float)));
  if (!out) throw Error(path.string() + ": cannot write");
}

Image read_raw_image(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(path.filename().string() + ": the renderer wrote no image");
  char magic[sizeof kRawMagic];
  int32_t header[3] = {0, 0, 0};
  in.read(magic, sizeof magic);
  in.read(reinterpret_cast<char*>(header), sizeof header);
  if (!in || std::memcmp(magic, kRawMagic, sizeof magic) != 0 || header[0] < 1 || header[1] < 1 || header[2] < 1 ||
      header[0] > kMaxRawDimension || header[1] > kMaxRawDimension || header[2] > 4)
    throw Error(path.filename().string() + ": not a raw image from the renderer");
  Image image(header[0], header[1], header[2]);
  in.read(reinterpret_cast<char*>(image.pixels.data()), static_cast<std::streamsize>(image.pixels.size() * sizeof(float)));
  if (!in) throw Error(path.filename().string() + ": the image is incomplete");
  return image;
}

nlohmann::json work_json(const LightVolumeWork& work, const LightVolumeState& state) {
  return {{"volume_lights", work.volume_lights},
          {"surface_pixels", work.surface_pixels},
          {"shaded_fragments", work.shaded_fragments},
          {"volume_coverage", work.volume_coverage},
          {"state", describe(state)}};
}

LightVolumeWork work_from_json(const nlohmann::json& json) {
  LightVolumeWork work;
  if (!json.is_object()) return work;
  work.volume_lights = json.value("volume_lights", 0);
  work.surface_pixels = json.value("surface_pixels", uint64_t{0});
  work.shaded_fragments = json.value("shaded_fragments", uint64_t{0});
  work.volume_coverage = json.value("volume_coverage", uint64_t{0});
  return work;
}

namespace {

struct RenderJob {
  int lab = 0;
  const LabWorker* worker = nullptr;
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
    return kChildEnvironmentError;
  }
  report["renderer"] = context->describe();
  report["seconds"]["context"] = seconds_since(t0);

  // One Renderer per (scene, isolated custom effect), built on first use; stage 6's
  // maps are made once per environment and shared between them.
  IblCache ibl_cache;
  // The Renderers build many of the same programs (display, debug, post, and lighting where
  // the scenes' light defines agree): each is compiled and linked once (gl_objects.h).
  LinkedProgramCache program_cache;
  // And each shader is assembled once: the lab's files are the child's own copy.
  AssembledShaderCache assembled_cache;
  std::map<std::pair<std::string, bool>, std::unique_ptr<Renderer>> renderers;
  // The settings of each Renderer's last frame. Checks that differ only in the view they
  // read (lab 1's G-buffer attachments of one scene, an image and its HDR buffer, lab 6's
  // maps beside the frame) read the frame already there instead of rendering it again:
  // the same scene, camera and settings give the same frame (21 of the 62 renders).
  std::map<std::pair<std::string, bool>, RenderSettings> last_frame;
  double compile = 0.0, render = 0.0, readback = 0.0;
  for (const RenderSpec* spec : lab_renders(job.lab)) {
    auto scene_it = job.worker->scenes->find(spec->scene);
    if (scene_it == job.worker->scenes->end()) {
      write_text(error_file, "scene '" + spec->scene + "' was not loaded");
      return kChildEnvironmentError;
    }
    const Scene& scene = scene_it->second;
    RenderSettings settings = render_settings(*spec);
    // Timings per Renderer (instructor/grading/measure.sh breaks a lab down by them).
    const std::string renderer_name = spec->scene + (spec->isolate_custom ? " (custom effect alone)" : "");
    report["renderer_of"][spec->id] = renderer_name;
    auto& renderer = renderers[{spec->scene, spec->isolate_custom}];
    if (!renderer) {
      auto t = Clock::now();
      try {
        ShaderLibrary library = spec->isolate_custom ? isolated_custom_library(stage, job.worker->lab_root)
                                                     : stage_library(stage, job.worker->lab_root);
        library.share_programs_through(&program_cache);
        library.keep_assembled_in(&assembled_cache);
        renderer = std::make_unique<Renderer>(stage, std::move(library), scene, settings, &ibl_cache);
      } catch (const NonFiniteMapError& e) {
        write_text(error_file, e.what());
        return kChildMapError;
      } catch (const Error& e) {
        write_text(error_file, e.what());
        return kChildShaderError;
      }
      double seconds = seconds_since(t);
      compile += seconds;
      report["seconds"]["compile_each"][renderer_name] = seconds;
    }
    try {
      renderer->settings() = settings;
      const auto key = std::make_pair(spec->scene, spec->isolate_custom);
      const auto last = last_frame.find(key);
      if (last == last_frame.end() || !same_frame_settings(last->second, settings)) {
        Camera camera = scene.camera ? *scene.camera : framing_camera(scene);
        auto t = Clock::now();
        // Lab 5's frames of one scene differ in post-processing alone: its passes run again,
        // not the whole frame (Renderer::render_reusing_lit_frame).
        renderer->render_reusing_lit_frame(
            frame_camera(camera, static_cast<float>(settings.width) / static_cast<float>(settings.height)));
        glFinish();
        double seconds = seconds_since(t);
        render += seconds;
        report["seconds"]["render_each"][spec->id] = seconds;
        last_frame[key] = settings;
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
      return kChildMapError;
    } catch (const Error& e) {
      write_text(error_file, std::string("while rendering ") + spec->scene + ": " + e.what());
      return kChildRenderError;
    }
  }
  report["programs_reused"] = program_cache.reused();
  report["seconds"]["compile"] = compile;
  report["seconds"]["render"] = render;
  report["seconds"]["readback"] = readback;
  report["seconds"]["total"] = seconds_since(t0);
  report["vm_peak_kib"] = peak_address_space_kib();  // what RLIMIT_AS limits
  write_text(job.out_dir / "child.json", json_text(report));
  return kChildOk;
}

}  // namespace

fs::path lab_folder(const fs::path& temp, int lab) { return temp / ("lab" + std::to_string(lab)); }

int serve_labs(const LabWorker& worker, TaskChannel& channel) {
  std::unique_ptr<GlContext> context;
  int status = kChildOk;
  while (status == kChildOk) {
    const int lab = channel.next_task();
    if (lab == 0) break;
    RenderJob job{lab, &worker, lab_folder(worker.temp, lab)};
    TaskChannel::log_to(job.out_dir / "child.log");
    if (chdir(job.out_dir.c_str()) != 0) {
      std::fprintf(stderr, "kit-grade: child: cannot enter %s: %s\n", job.out_dir.c_str(), std::strerror(errno));
      status = kChildEnvironmentError;
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
