#include "frames/lab_frames.h"

#include <nlohmann/json.hpp>

#include <chrono>
#include <utility>
#include <vector>

#include "base/error.h"
#include "frames/light_shares.h"
#include "gl/gl.h"
#include "gl/gl_flavour.h"

namespace fs = std::filesystem;

namespace kit::grade {

namespace {

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

// The camera every render of a check is drawn with: the scene's first, else its framing.
FrameCamera grading_camera(const Scene& scene, const RenderSettings& settings) {
  return frame_camera(chosen_camera(scene, -1), static_cast<float>(settings.width) / static_cast<float>(settings.height));
}

}  // namespace

bool custom_effect_isolated(const Stage& stage) { return fs::is_directory(kit_root() / "solutions" / stage.folder); }

LabFrames::LabFrames(const Stage& stage, fs::path lab_root, const std::map<std::string, Scene>& scenes)
    : stage_(stage), lab_root_(std::move(lab_root)), scenes_(scenes) {}

std::string LabFrames::renderer_name(const RenderSpec& spec) {
  return spec.scene + (spec.isolate_custom ? " (custom effect alone)" : "");
}

Renderer& LabFrames::renderer_for(const RenderSpec& spec, double* compile_seconds) {
  auto& renderer = renderers_[{spec.scene, spec.isolate_custom}];
  if (renderer) return *renderer;
  const auto scene = scenes_.find(spec.scene);
  if (scene == scenes_.end()) throw Error("scene '" + spec.scene + "' was not loaded");
  const auto t = std::chrono::steady_clock::now();
  ShaderLibrary library = spec.isolate_custom ? isolated_custom_library(stage_, lab_root_) : stage_library(stage_, lab_root_);
  library.share_programs_through(&program_cache_);
  library.keep_assembled_in(&assembled_cache_);
  renderer = std::make_unique<Renderer>(stage_, std::move(library), scene->second, render_settings(spec), &ibl_cache_);
  if (compile_seconds) *compile_seconds = seconds_since(t);
  return *renderer;
}

double LabFrames::draw(const RenderSpec& spec) {
  Renderer& renderer = renderer_for(spec);
  const RenderSettings settings = render_settings(spec);
  renderer.settings() = settings;
  const auto key = std::make_pair(spec.scene, spec.isolate_custom);
  const auto last = last_frame_.find(key);
  if (last != last_frame_.end() && same_frame_settings(last->second, settings)) return 0.0;
  const auto t = std::chrono::steady_clock::now();
  // Lab 5's frames of one scene differ in post-processing alone: its passes run again,
  // not the whole frame (Renderer::render_reusing_lit_frame).
  renderer.render_reusing_lit_frame(grading_camera(renderer.scene(), settings));
  glFinish();
  last_frame_[key] = settings;
  return seconds_since(t);
}

Image LabFrames::light_shares(const RenderSpec& spec) {
  Renderer& renderer = renderer_for(spec);
  RenderSettings settings = render_settings(spec);
  settings.count_light_volume_work = false;  // no check reads these frames' work
  const FrameCamera frame = grading_camera(renderer.scene(), settings);
  const int lights = static_cast<int>(frame_lights(renderer.scene(), stage_, settings).size());
  std::vector<Image> alone;
  Image none;
  for (int light = 0; light <= lights; ++light) {  // the last: past every light, none
    settings.only_light = light;
    renderer.settings() = settings;
    renderer.render(frame);
    (light < lights ? alone.emplace_back() : none) = renderer.read_view(View::Hdr, true);
  }
  last_frame_.erase({spec.scene, spec.isolate_custom});  // its frame is the one without lights
  return light_shares_image(alone, none);
}

namespace {

nlohmann::json evidence_json(const VolumeEvidence& v) {
  return {{"lights", v.lights},
          {"footprint", v.footprint},
          {"missing", v.missing},
          {"extra", v.extra},
          {"must_shade", v.must_shade},
          {"shaded_wrong", v.shaded_wrong},
          {"adds", v.adds},
          {"worst_volume_light", v.worst_volume_light},
          {"worst_footprint", v.worst_footprint},
          {"worst_missing", v.worst_missing},
          {"worst_extra", v.worst_extra},
          {"worst_state_light", v.worst_state_light},
          {"worst_must_shade", v.worst_must_shade},
          {"worst_shaded", v.worst_shaded}};
}

}  // namespace

nlohmann::json work_json(const LightVolumeWork& work, const LightVolumeState& state) {
  return {{"volume_lights", work.volume_lights},
          {"surface_pixels", work.surface_pixels},
          {"shaded_fragments", work.shaded_fragments},
          {"volume_coverage", work.volume_coverage},
          {"state", describe(state)},
          {"evidence", evidence_json(work.evidence)},
          // Whether the per-light counts were taken: not where a query only says 0 or 1 (WebGL2).
          {"counted", samples_passed_counts()}};
}

LightVolumeWork work_from_json(const nlohmann::json& json) {
  LightVolumeWork work;
  if (!json.is_object()) return work;
  work.volume_lights = json.value("volume_lights", 0);
  work.surface_pixels = json.value("surface_pixels", uint64_t{0});
  work.shaded_fragments = json.value("shaded_fragments", uint64_t{0});
  work.volume_coverage = json.value("volume_coverage", uint64_t{0});
  const nlohmann::json e = json.value("evidence", nlohmann::json::object());
  if (e.is_object()) {
    VolumeEvidence& v = work.evidence;
    v.lights = e.value("lights", 0);
    v.footprint = e.value("footprint", uint64_t{0});
    v.missing = e.value("missing", uint64_t{0});
    v.extra = e.value("extra", uint64_t{0});
    v.must_shade = e.value("must_shade", uint64_t{0});
    v.shaded_wrong = e.value("shaded_wrong", uint64_t{0});
    v.adds = e.value("adds", true);
    v.worst_volume_light = e.value("worst_volume_light", -1);
    v.worst_footprint = e.value("worst_footprint", uint64_t{0});
    v.worst_missing = e.value("worst_missing", uint64_t{0});
    v.worst_extra = e.value("worst_extra", uint64_t{0});
    v.worst_state_light = e.value("worst_state_light", -1);
    v.worst_must_shade = e.value("worst_must_shade", uint64_t{0});
    v.worst_shaded = e.value("worst_shaded", uint64_t{0});
  }
  return work;
}

}  // namespace kit::grade
