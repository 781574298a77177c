#pragma once
// Shared helpers for the kit's GoogleTest programs: one headless context per
// test process, cached scenes, stage renders, and temp folders.
#include <gtest/gtest.h>

#include <filesystem>
#include <memory>
#include <string>

#include "gl/context.h"
#include "images/image_io.h"
#include "base/no_dangling.h"
#include "render/renderer.h"

namespace kit::test {

// The process's headless OSMesa context, created on first use and kept current.
GlContext& context();

// A kit scene by name ("default", "sphere", ...) or a path, loaded once per process.
KIT_NO_DANGLING const Scene& scene(const std::string& name_or_path);  // cached: lives as long as the program

// The kit::Error message loading the scene file `path` throws; fails the test when it loads.
std::string scene_load_error(const std::filesystem::path& path);

// Expects loading the scene file `path` to throw a kit::Error whose message names the
// file and holds `phrase`.
void expect_scene_error(const std::filesystem::path& path, const std::string& phrase);

// The frame size most GPU tests render at: big enough for thousands of samples per
// frame, small enough to keep each test program at a few seconds.
constexpr int kSmallWidth = 160, kSmallHeight = 120;
// Default RenderSettings at that size (or another).
RenderSettings small_settings(int width = kSmallWidth, int height = kSmallHeight);

// Builds a Renderer for `stage` (name or number) with lab files from `lab_root`
// (solutions/ by default) and renders one frame from the scene's camera.
std::unique_ptr<Renderer> render_stage(const std::string& stage, const std::string& scene_name,
                                       RenderSettings settings = {},
                                       const std::filesystem::path& lab_root = kit_root() / "solutions");

// A fresh, empty folder under the build tree for this test's files.
std::filesystem::path temp_dir(const std::string& name);

// The build folder the tests were built in (build/<preset>).
std::filesystem::path build_dir();

// Path of a program built in build/<preset>/tools (kit-render, kit-grade, ...).
std::string tool(const std::string& name);

// Runs a shell command, returns its exit status; its stdout+stderr go to *output when given.
int run(const std::string& command, std::string* output = nullptr);

// Largest absolute per-channel difference between two images of equal size.
float max_abs_difference(const Image& a, const Image& b);

}  // namespace kit::test
