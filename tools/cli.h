#pragma once
// Flags shared by every kit program (kit-render, kit-view, ...), so each one
// takes the same --stage/--shaders/--scene/--size/... spelling.
#include <functional>
#include <string>
#include <vector>

#include "renderer.h"

namespace kit {

struct CommonOptions {
  std::string stage = "gbuffer";
  std::string shaders;           // root holding NN-name/ folders; empty = solutions/
  std::string scene = "default"; // scene name or .gltf path
  std::string backend = "osmesa";
  RenderSettings settings;
};

// Help text for the shared flags.
const char* common_options_help();

// Walks argv. Shared flags fill `options`; any other flag is offered to
// `extra(flag, value)`, which returns how many arguments it consumed (1 or 2),
// or 0 when it does not know the flag; `value()` is the argument after the flag,
// and throws "FLAG needs a value" when there is none. Throws kit::Error.
using OptionValue = std::function<std::string()>;
void parse_options(int argc, char** argv, CommonOptions& options,
                   const std::function<int(const std::string&, const OptionValue&)>& extra);

// "640x480" -> width, height.
void parse_size(const std::string& text, int* width, int* height);
bool parse_on_off(const std::string& text, const std::string& flag);

// The folder of lab files a stage is assembled from (solutions/ by default).
std::filesystem::path shaders_root(const CommonOptions& options);

}  // namespace kit
