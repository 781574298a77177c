#pragma once
// The lab sequence. Adding a lab is one folder under labs/ and solutions/ plus
// one row in kStages (stages.cpp). Stage names are the same in the CLI, the
// folders and the reports.
#include <filesystem>
#include <string>
#include <vector>

#include "shader_source.h"

namespace kit {

struct Stage {
  int number;                      // 1-based position in the sequence
  std::string name;                // "gbuffer", "lighting", ...
  std::string folder;              // "01-gbuffer", ...
  std::vector<std::string> files;  // the files this step adds or changes
  bool lighting;                   // runs the full-screen lighting pass
  bool postprocess;                // runs bright pass, blur, composite and the custom effect
};

const std::vector<Stage>& stages();
// By name ("lighting") or number ("2"); throws kit::Error listing the valid names.
const Stage& find_stage(const std::string& name_or_number);

// The kit's source tree (holds framework/shaders/, labs/, solutions/). Taken from
// $KIT_ROOT when set, else the path compiled in.
std::filesystem::path kit_root();
// The framework's shaders and shared GLSL modules: <kit root>/framework/shaders.
std::filesystem::path shaders_dir();
// Scenes generated at build time, by name ("default") or as a path to a .gltf file.
std::string resolve_scene(const std::string& name_or_path);

// The shader folders a stage is assembled from: `lab_root`/NN-name for this
// step's files, then solutions/ of every earlier step (latest first), then framework/shaders/.
ShaderLibrary stage_library(const Stage& stage, const std::filesystem::path& lab_root);

}  // namespace kit
