#include "render/stages.h"

#include <cstdlib>

#include "base/error.h"

namespace fs = std::filesystem;

namespace kit {

const std::vector<Stage>& stages() {
  static const std::vector<Stage> kStages = {
      // number, name, folder, files, lighting pass, postprocess
      {1, "gbuffer", "01-gbuffer", {"gbuffer.vert", "gbuffer.frag"}, false, false},
      {2, "lighting", "02-lighting", {"lighting.frag", "brdf.glsl"}, true, false},
      {3, "attenuation", "03-attenuation", {"attenuation.glsl", "tonemap.glsl"}, true, false},
      {4, "normalmap", "04-normalmap", {"gbuffer.vert", "gbuffer.frag"}, true, false},
      {5, "postprocess", "05-postprocess", {"bright.frag", "blur.frag", "composite.frag", "custom_effect.frag"}, true, true},
      {6, "ibl", "06-ibl", {"ibl.frag", "irradiance.frag", "prefilter.frag", "brdf_lut.frag"}, true, true, true},
      // Direct light only: the environment's light would hide the small lights this lab is about.
      {7, "lightvolumes", "07-lightvolumes", {"light_volume.vert", "light_volume.frag"}, true, true, false, true},
  };
  return kStages;
}

const Stage& find_stage(const std::string& name_or_number) {
  std::string names;
  for (const Stage& s : stages()) {
    if (s.name == name_or_number || std::to_string(s.number) == name_or_number || s.folder == name_or_number) return s;
    names += (names.empty() ? "" : ", ") + s.name;
  }
  throw Error("unknown stage '" + name_or_number + "' (stages: " + names + ")");
}

const Stage& find_stage(int number) {
  for (const Stage& s : stages())
    if (s.number == number) return s;
  throw Error("unknown stage " + std::to_string(number) + " (stages: 1-" + std::to_string(stages().size()) + ")");
}

fs::path kit_root() {
  const char* env = std::getenv("KIT_ROOT");
  return fs::path(env && *env ? env : KIT_SOURCE_DIR);
}

fs::path shaders_dir() { return kit_root() / "shaders"; }

fs::path scene_dir() {
  const char* env = std::getenv("KIT_SCENE_DIR");
  return env && *env ? fs::path(env) : fs::path(KIT_SCENE_DIR);
}

std::string resolve_scene(const std::string& name_or_path) {
  bool is_name = name_or_path.find('/') == std::string::npos && name_or_path.find('.') == std::string::npos;
  if (!is_name) return name_or_path;
  return (scene_dir() / name_or_path / (name_or_path + ".gltf")).string();
}

namespace {
// The first earlier lab whose solution folder is missing, or nullptr: the one
// test behind require_earlier_solutions, gradable_labs and labs_with_solutions.
const Stage* first_missing_solution(const Stage& stage) {
  for (const Stage& earlier : stages()) {
    if (earlier.number >= stage.number) break;
    if (!fs::is_directory(kit_root() / "solutions" / earlier.folder)) return &earlier;
  }
  return nullptr;
}
bool has_earlier_solutions(const Stage& stage) { return first_missing_solution(stage) == nullptr; }
}  // namespace

void require_earlier_solutions(const Stage& stage) {
  if (const Stage* missing = first_missing_solution(stage))
    throw Error("stage " + std::to_string(stage.number) + " (" + stage.name + ") is built on the solution of lab " +
                std::to_string(missing->number) + ", and " + (kit_root() / "solutions" / missing->folder).string() +
                " is missing (a student copy gets it with the release after lab " + std::to_string(missing->number) +
                ")");
}

std::vector<int> gradable_labs() {
  std::vector<int> labs;
  for (const Stage& s : stages())
    if (fs::is_directory(kit_root() / "labs" / s.folder) && has_earlier_solutions(s)) labs.push_back(s.number);
  return labs;
}

std::vector<int> labs_with_solutions() {
  std::vector<int> labs;
  for (const Stage& s : stages())
    if (fs::is_directory(kit_root() / "solutions" / s.folder) && has_earlier_solutions(s)) labs.push_back(s.number);
  return labs;
}

ShaderLibrary stage_library(const Stage& stage, const fs::path& lab_root) {
  require_earlier_solutions(stage);
  fs::path root = kit_root();
  std::vector<ShaderFolder> folders;
  std::string lab_label = lab_root.filename().string();
  if (lab_label.empty()) lab_label = lab_root.parent_path().filename().string();
  folders.push_back({lab_root / stage.folder, lab_label + "/" + stage.folder, stage.files});
  for (auto it = stages().rbegin(); it != stages().rend(); ++it) {
    if (it->number >= stage.number) continue;
    folders.push_back({root / "solutions" / it->folder, "solutions/" + it->folder, it->files});
  }
  folders.push_back({shaders_dir(), "shaders", {}});
  return ShaderLibrary(std::move(folders));
}

}  // namespace kit
