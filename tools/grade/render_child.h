#pragma once
// What a render child does: one lab of one submission, every render of that lab
// (lab_renders) in one process with one GL context, one Renderer per scene, so
// each shader is compiled once and only uniforms change between settings, and
// one IblCache, so stage 6's maps are precomputed once per environment.
// Results go to files in the task folder: one raw image per render, child.json
// (timings, also per Renderer and per render, the GL renderer's name, NaN/Inf
// counts of the HDR buffer) and, when the lab could not be rendered, error.txt
// with the kit::Error text (compiler logs already mapped to the submission's
// file and line).
#include <filesystem>
#include <map>
#include <string>

#include <nlohmann/json.hpp>

#include "gl/context.h"
#include "images/image_io.h"
#include "scene/scene.h"

namespace kit::grade {

// Exit statuses of a render child.
constexpr int kChildOk = 0;
constexpr int kChildShaderError = 2;       // a shader did not assemble, compile or link
constexpr int kChildEnvironmentError = 3;  // no GL context or scene: the grader's problem
constexpr int kChildRenderError = 4;       // a GL error while drawing
constexpr int kChildMapError = 5;          // a lab 6 precompute shader wrote NaN or Inf into a map (ibl.h)

struct RenderJob {
  int lab = 0;
  std::filesystem::path lab_root;  // the sanitized copy of the submission's lab files
  std::filesystem::path out_dir;   // where the child writes its files
  Backend backend = kDefaultHeadlessBackend;
  Device device = Device::Software;
  const std::map<std::string, Scene>* scenes = nullptr;  // loaded by the parent before forking
};

// Whether lab `stage`'s custom effect is isolated on the kit's own solution of the lab
// (render_child.cpp, isolated_custom_library): false in a kit without that solution (a
// student copy for lab 5, a Classroom 50 bundle), where the effect is rendered on the
// submission's own bloom and the report says so (kOwnBloomNote).
bool custom_effect_isolated(const Stage& stage);

// Runs in the child; returns its exit status.
int render_lab(const RenderJob& job);

// A lab 7 frame's counted work (render/light_volumes.h) as child.json holds it, and back (zeros
// for what a report lacks).
nlohmann::json work_json(const LightVolumeWork& work, const LightVolumeState& state);
LightVolumeWork work_from_json(const nlohmann::json& json);

// Raw float images between child and parent (not an image file format): the
// 8 bytes "KITRAW1\0", width, height and channels as int32, then the floats.
void write_raw_image(const std::filesystem::path& path, const Image& image);
Image read_raw_image(const std::filesystem::path& path);  // throws kit::Error
std::filesystem::path raw_image_path(const std::filesystem::path& dir, const std::string& render_id);

}  // namespace kit::grade
