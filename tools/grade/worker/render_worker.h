#pragma once
// What a render worker does: labs of one submission, one after another in one process
// with one GL context; for each lab, every render of that lab (lab_renders), one
// Renderer per scene, so each shader is compiled once and only uniforms change between
// settings, and one IblCache, so stage 6's maps are precomputed once per environment.
// Results go to files in the lab's task folder: one raw image per render, child.json
// (timings, also per Renderer and per render, the GL renderer's name, NaN/Inf
// counts of the HDR buffer) and, when the lab could not be rendered, error.txt
// with the kit::Error text (compiler logs already mapped to the submission's
// file and line).
#include <filesystem>
#include <map>
#include <string>

#include <nlohmann/json_fwd.hpp>

#include "gl/context.h"
#include "intake/sandbox.h"
#include "scene/scene.h"

namespace kit::grade {

// A lab's status in a worker's report, and the worker's exit status after it.
constexpr int kWorkerOk = 0;
constexpr int kWorkerShaderError = 2;       // a shader did not assemble, compile or link
constexpr int kWorkerEnvironmentError = 3;  // no GL context or scene: the grader's problem
constexpr int kWorkerRenderError = 4;       // a GL error while drawing
constexpr int kWorkerMapError = 5;          // a lab 6 precompute shader wrote NaN or Inf into a map (ibl.h)

// A render worker: the labs of one submission, one after another as the grader sends
// them (sandbox.h, TaskChannel), in one process with one GL context. A child for each lab
// paid again for its fork, its context and llvmpipe's triangle-setup code, which Mesa does
// not cache (a tenth of a warm run's CPU; docs/performance.md, Grading).
struct RenderWorker {
  std::filesystem::path lab_root;  // the sanitized copy of the submission's lab files
  std::filesystem::path temp;      // lab N writes its files in lab_folder(temp, N)
  Backend backend = default_headless_backend();
  Device device = Device::Software;
  const std::map<std::string, Scene>* scenes = nullptr;  // loaded by the parent before forking
  const nlohmann::json* probes_reference = nullptr;        // probes.json (function_probes.h), or null
  bool describing_renders = false;  // --update-references: RenderSpec::describes_pixels_only too

  // Runs in the worker: renders each lab the channel names into its folder, with that
  // folder as its working directory and its child.log as stdout and stderr, and reports
  // the lab's status. Goes on only after a lab that rendered; returns the exit status.
  int serve(TaskChannel& channel) const;
};

// Where lab `lab` of a worker writes its files (the grader makes the folder first).
std::filesystem::path lab_folder(const std::filesystem::path& temp, int lab);

}  // namespace kit::grade
