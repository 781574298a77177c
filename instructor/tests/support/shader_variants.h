#pragma once
// Naive variants of the solution shaders, for tests that show what a guard prevents:
// a full copy of solutions/ in a temp lab root with single lines swapped, rendered
// through the normal pipeline.
#include <filesystem>
#include <string>
#include <vector>

#include "gl/shader_source.h"
#include "render/stages.h"

namespace kit::test {

// One line of a solution file and what a naive implementation writes instead.
struct LineSwap {
  std::string file;   // relative to solutions/, e.g. "02-lighting/brdf.glsl"
  std::string kit;    // text of the kit's line (a unique substring of the file)
  std::string naive;  // what replaces that text
};

// A lab root under the build tree (temp_dir(name)) holding a copy of every
// solutions/NN-name folder with `swaps` applied. A swap whose `kit` text does not
// occur exactly once throws std::runtime_error, so a solution edit that moves a
// guard fails the test loudly instead of silently testing an unchanged shader.
std::filesystem::path variant_root(const std::string& name, const std::vector<LineSwap>& swaps);

// The shader folders for `stage` with its own step and every earlier step taken
// from `root` (a full lab root, as variant_root makes), then shaders/. Unlike
// stage_library, a variant of an earlier step (say lab 2's lighting.frag) is then
// used by a later stage too.
ShaderLibrary full_root_library(const Stage& stage, const std::filesystem::path& root);

}  // namespace kit::test
