#pragma once
// The lab sequence. Adding a lab is one folder under labs/ and solutions/ plus
// one row in kStages (stages.cpp). Stage names are the same in the CLI, the
// folders and the reports.
#include <filesystem>
#include <string>
#include <vector>

#include "base/no_dangling.h"
#include "gl/shader_source.h"

namespace kit {

struct Stage {
  int number;                      // 1-based position in the sequence
  std::string name;                // "gbuffer", "lighting", ...
  std::string folder;              // "01-gbuffer", ...
  std::vector<std::string> files;  // the files this step adds or changes
  bool lighting;                   // runs the full-screen lighting pass
  bool postprocess;                // runs bright pass, blur, composite and the custom effect
  bool ibl = false;                // lit by an environment too: lab 6's precompute passes and IBL pass (ibl.h)
  bool light_volumes = false;      // point and spot lights drawn as light volumes (light_volumes.h); the
                                   // full-screen pass keeps the directional lights and emission
};

const std::vector<Stage>& stages();
// By name ("lighting") or number ("2"); throws kit::Error listing the valid names.
KIT_NO_DANGLING const Stage& find_stage(const std::string& name_or_number);
// The stage numbered `number` (1-7). Taking the int itself, not std::to_string(number):
// GCC 14's -Wdangling-reference warns at every reference bound from a call given a temporary.
KIT_NO_DANGLING const Stage& find_stage(int number);

// The kit's source tree (holds shaders/, labs/, solutions/). Taken from
// $KIT_ROOT when set, else the path compiled in.
std::filesystem::path kit_root();
// The framework's shaders and shared GLSL modules: <kit root>/shaders.
std::filesystem::path shaders_dir();
// Where the build wrote the kit's generated scenes and environments: $KIT_SCENE_DIR
// when set, else the path compiled in.
std::filesystem::path scene_dir();
// Scenes generated at build time, by name ("default") or as a path to a .gltf file.
std::string resolve_scene(const std::string& name_or_path);

// Throws kit::Error when a solution `stage` is assembled on is missing from
// <kit root>/solutions (a student copy for lab N has those of labs 1..N-1 only).
void require_earlier_solutions(const Stage& stage);
// The labs this kit can grade and render from labs/: a starter folder in labs/ and
// the solutions of every earlier lab. All of them in the instructor's kit; lab N
// alone in a student copy for lab N.
std::vector<int> gradable_labs();
// The labs whose own solution and every earlier one are in <kit root>/solutions.
std::vector<int> labs_with_solutions();

// The shader folders a stage is assembled from: `lab_root`/NN-name for this
// step's files, then solutions/ of every earlier step (latest first), then shaders/.
ShaderLibrary stage_library(const Stage& stage, const std::filesystem::path& lab_root);

}  // namespace kit
