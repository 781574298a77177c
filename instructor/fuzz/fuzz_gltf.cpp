// libFuzzer harness: the glTF loader (common/scene/scene.*, common/base/safe_file.*, common/scene/draco_mesh.*).
//
// The input is the text of a .gltf file, or a .glb when it starts with "glTF",
// written as scene.gltf / scene.glb into a private temp folder that also holds
// copies of the kit's generated scenes' buffers and images (sphere.bin,
// default.bin, checker.png, ...; from $KIT_SCENE_DIR, which run_fuzz.sh sets), so
// a mutated scene can name real files. kit::load_scene either returns a scene or
// throws kit::Error: both are expected. Anything else (a crash, an ASan or UBSan
// report, any other exception, a hang past -timeout) is a finding.
#include <stdlib.h>
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>

#include "base/error.h"
#include "scene/scene.h"

namespace fs = std::filesystem;

namespace {

fs::path g_folder;  // the private temp folder

void remove_folder() {
  std::error_code ec;
  if (!g_folder.empty()) fs::remove_all(g_folder, ec);
}

[[noreturn]] void fail_setup(const std::string& what) {
  std::fprintf(stderr, "fuzz_gltf: %s\n", what.c_str());
  std::exit(2);
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  const char* scenes = std::getenv("KIT_SCENE_DIR");
  if (!scenes || !*scenes || !fs::is_directory(scenes))
    fail_setup("set KIT_SCENE_DIR to the kit's generated scenes (build/default/scenes; run_fuzz.sh does)");
  std::string pattern = (fs::temp_directory_path() / "kit-fuzz-gltf-XXXXXX").string();
  if (!mkdtemp(pattern.data())) fail_setup("cannot create a temp folder from " + pattern);
  g_folder = pattern;
  std::atexit(remove_folder);
  // Every buffer and image of every generated scene, side by side (the same name is the same file).
  size_t copied = 0;
  for (const auto& scene : fs::directory_iterator(scenes)) {
    if (!scene.is_directory()) continue;
    for (const auto& file : fs::directory_iterator(scene.path())) {
      std::string ext = file.path().extension().string();
      if ((ext == ".bin" || ext == ".png") && !fs::exists(g_folder / file.path().filename())) {
        fs::copy_file(file.path(), g_folder / file.path().filename());
        ++copied;
      }
    }
  }
  if (copied == 0) fail_setup(std::string("no .bin or .png file in the scene folders of ") + scenes);
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  bool glb = size >= 4 && std::memcmp(data, "glTF", 4) == 0;
  fs::path scene = g_folder / (glb ? "scene.glb" : "scene.gltf");
  {
    std::ofstream out(scene, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
    if (!out) fail_setup("cannot write " + scene.string());
  }
  try {
    kit::Scene loaded = kit::load_scene(scene.string());
    // A loaded scene is usable: its framing camera is computed from its bounds.
    kit::framing_camera(loaded);
  } catch (const kit::Error&) {
    // The expected outcome for a broken file.
  }
  return 0;
}
