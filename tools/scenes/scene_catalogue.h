// The kit's scenes: what each is for (the checks and tests that use it) and how it is built.
#pragma once

#include <filesystem>

namespace kit_scenes {

// OUT_DIR/<name>/ for every scene of the build (tools/scenes.cmake lists them), the OBJ
// cube and lab 6's environments (OUT_DIR/environments/).
void write_kit_scenes(const std::filesystem::path& out_dir);
// OUT_DIR/heavy: 1,048,576 triangles, 16 textures of 2048x2048 (load time and memory).
void write_heavy_scene(const std::filesystem::path& out_dir);

}  // namespace kit_scenes
