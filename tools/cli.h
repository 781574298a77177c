#pragma once
// Flags shared by every kit program (kit-render, kit-view, ...), so each one
// takes the same --stage/--shaders/--scene/--size/... spelling.
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "gl/context.h"
#include "scene/look_at.h"
#include "render/renderer.h"
#include "base/watchdog.h"

namespace kit {

struct CommonOptions {
  std::string stage;             // --stage; empty: from a lab folder given to --shaders, else gbuffer
  std::string shaders;           // --shaders: a folder of NN-name/ lab folders, or one of them; empty: labs/
  bool solution = false;         // --solution: the reference solutions (solutions/) instead of labs/
  std::string scene = "default"; // scene name or .gltf/.glb/.obj path
  int camera = -1;               // --camera N: the scene file's camera N (kit::chosen_camera); -1: its first
  std::string backend = default_headless_backend_name();  // osmesa where built, else egl
  double timeout = kDefaultTimeoutSeconds;  // --timeout: seconds of GL work before the watchdog ends the run; 0: none
  std::optional<LookAt> look_at;  // --look-at: the camera; absent: the scene's, else one framing the bounds
  RenderSettings settings;        // default_light_rig on; --no-default-lights turns it off

  CommonOptions() { settings.default_light_rig = true; }
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

// The camera a run starts from: --look-at's, else the file's camera --camera N (chosen_camera), else its
// first, else framing_camera's. Giving both --look-at and --camera is refused by parse_options.
Camera initial_camera(const Scene& scene, const CommonOptions& options);

// Says on stderr, as "TOOL: note: ...", when a lit stage shows the scene through the
// default light rig (renderer.h) because it has no lights of its own.
void note_default_light_rig(const char* tool, const Scene& scene, const Stage& stage, const RenderSettings& settings);

// "640x480" -> width, height.
void parse_size(const std::string& text, int* width, int* height);
bool parse_on_off(const std::string& text, const std::string& flag);
// The whole number `text` spells (decimal digits, nothing after them) when it lies
// in [min, max]; nothing otherwise. Callers say which flag expected what.
std::optional<long> parse_whole_number(const std::string& text, long min, long max);

// Which lab files a run renders: the stage and the folder holding the NN-name
// lab folders (the root stage_library takes).
struct LabSelection {
  const Stage* stage = nullptr;
  std::filesystem::path root;
};
// --solution: solutions/; --shaders DIR: DIR, or DIR's parent when DIR is a lab
// folder itself (labs/02-lighting), whose stage is then the default; otherwise
// labs/. Throws kit::Error when the folders are missing (see check_lab_folder)
// or --stage names another lab than the folder given.
LabSelection select_lab(const CommonOptions& options);
// Throws kit::Error naming root/NN-name and how to fix it when that is not a folder.
void check_lab_folder(const CommonOptions& options, const std::filesystem::path& root, const Stage& stage);

}  // namespace kit
