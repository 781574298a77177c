// libFuzzer harness: the shader assembler (common/gl/shader_source.*) on the
// path the Renderer takes before it needs GL: kit::stage_library over a lab
// root, kit::check_stage_interfaces (the varying check the Renderer runs first),
// then ShaderLibrary::assemble of every top-level shader that reads the file
// (reading, the #version rule, #include resolution, line mapping), and
// AssembledShader::map_log on the input's text as a compiler log.
//
// A private temp lab root holds every lab's folder (NN-name/) filled with the
// reference solutions' files. The input's first byte picks one lab file (in
// kit::stages() order: 01-gbuffer/gbuffer.vert, 01-gbuffer/gbuffer.frag,
// 02-lighting/lighting.frag, ...), the rest of the input replaces that file's
// text, and the solution's text is put back afterwards. kit::Error is the
// expected outcome for a bad file; anything else is a finding.
//
// With $KIT_FUZZ_WRITE_SEEDS set to a folder, it writes its seed inputs there and
// exits: each lab file's starter (labs/) and solution text behind its byte, and
// the framework's shaders (shaders/) in the slot of a file of their kind.
#include <stdlib.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <set>
#include <string>
#include <vector>

#include "base/error.h"
#include "render/interface_check.h"
#include "gl/shader_source.h"
#include "render/stages.h"

namespace fs = std::filesystem;

namespace {

struct LabFile {
  const kit::Stage* stage;
  std::string name;
  fs::path path;                   // in the temp lab root
  std::string solution;            // the reference text, restored after each input
  std::vector<std::string> users;  // the top-level shaders whose assembly reads this file
};

fs::path g_root;
std::vector<LabFile> g_files;

void remove_root() {
  std::error_code ec;
  if (!g_root.empty()) fs::remove_all(g_root, ec);
}

[[noreturn]] void fail_setup(const std::string& what) {
  std::fprintf(stderr, "fuzz_shader: %s\n", what.c_str());
  std::exit(2);
}

std::string read_all(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) fail_setup("cannot read " + path.string());
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

void write_all(const fs::path& path, const char* data, size_t size) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(data, static_cast<std::streamsize>(size));
  if (!out) fail_setup("cannot write " + path.string());
}

bool is_top_level(const std::string& name) {
  auto ends = [&](const char* ext) { return name.size() > 5 && name.compare(name.size() - 5, 5, ext) == 0; };
  return ends(".vert") || ends(".frag") || ends(".comp");
}

// Every top-level shader name the stage's library can supply.
std::vector<std::string> top_level_names(const kit::ShaderLibrary& library) {
  std::set<std::string> names;
  for (const kit::ShaderFolder& folder : library.folders()) {
    if (!folder.only.empty()) {
      for (const std::string& n : folder.only)
        if (is_top_level(n)) names.insert(n);
      continue;
    }
    std::error_code ec;
    for (const auto& entry : fs::directory_iterator(folder.path, ec))
      if (is_top_level(entry.path().filename().string())) names.insert(entry.path().filename().string());
  }
  return {names.begin(), names.end()};
}

// Writes the seed inputs into `dir` (see the top of this file).
void write_seeds(const fs::path& dir) {
  fs::create_directories(dir);
  auto seed = [&](const std::string& name, size_t slot, const std::string& text) {
    std::string input = std::string(1, static_cast<char>(slot)) + text;
    write_all(dir / name, input.data(), input.size());
  };
  auto slot_of_kind = [&](const std::string& ext) -> size_t {
    for (size_t i = 0; i < g_files.size(); ++i)
      if (fs::path(g_files[i].name).extension() == ext) return i;
    return 0;
  };
  for (size_t i = 0; i < g_files.size(); ++i) {
    const LabFile& f = g_files[i];
    std::string stem = f.stage->folder + "-" + f.name;
    seed("solution-" + stem, i, f.solution);
    fs::path starter = kit::kit_root() / "labs" / f.stage->folder / f.name;
    if (fs::exists(starter)) seed("labs-" + stem, i, read_all(starter));
  }
  for (const auto& entry : fs::directory_iterator(kit::shaders_dir())) {
    std::string ext = entry.path().extension().string();
    if (ext == ".vert" || ext == ".frag" || ext == ".glsl")
      seed("shaders-" + entry.path().filename().string(), slot_of_kind(ext), read_all(entry.path()));
  }
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  std::string pattern = (fs::temp_directory_path() / "kit-fuzz-shader-XXXXXX").string();
  if (!mkdtemp(pattern.data())) fail_setup("cannot create a temp folder from " + pattern);
  g_root = fs::path(pattern) / "labs";
  std::atexit(remove_root);
  for (const kit::Stage& stage : kit::stages()) {
    fs::create_directories(g_root / stage.folder);
    for (const std::string& file : stage.files) {
      std::string text = read_all(kit::kit_root() / "solutions" / stage.folder / file);
      write_all(g_root / stage.folder / file, text.data(), text.size());
      g_files.push_back({&stage, file, g_root / stage.folder / file, text, {}});
    }
  }
  // Which top-level shaders read each lab file, found by assembling them all once.
  for (LabFile& f : g_files) {
    kit::ShaderLibrary library = kit::stage_library(*f.stage, g_root);
    fs::path real = fs::canonical(f.path);
    for (const std::string& name : top_level_names(library)) {
      try {
        kit::AssembledShader shader = library.assemble(name);
        if (std::find(shader.paths.begin(), shader.paths.end(), real) != shader.paths.end()) f.users.push_back(name);
      } catch (const kit::Error& e) {
        // A function probe's shader (tools/grade/frames/probe_pass.h) includes the file of the lab it
        // probes, which the stages before that lab do not have: the grader builds it for that
        // lab alone.
        if (name.rfind("probe_", 0) == 0) continue;
        fail_setup("the reference shaders do not assemble: " + std::string(e.what()));
      }
    }
    if (f.users.empty()) fail_setup(f.stage->folder + "/" + f.name + " is read by no top-level shader");
  }
  if (const char* seeds = std::getenv("KIT_FUZZ_WRITE_SEEDS"); seeds && *seeds) {
    write_seeds(seeds);
    std::exit(0);
  }
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size == 0) return 0;
  LabFile& file = g_files[data[0] % g_files.size()];
  const char* text = reinterpret_cast<const char*>(data + 1);
  write_all(file.path, text, size - 1);
  kit::ShaderLibrary library = kit::stage_library(*file.stage, g_root);
  try {
    kit::check_stage_interfaces(*file.stage, library);
  } catch (const kit::Error&) {
  }
  kit::AssembledShader last;
  for (const std::string& name : file.users) {
    try {
      last = library.assemble(name);
    } catch (const kit::Error&) {
    }
  }
  // The input's text as a compiler log, mapped onto the last shader assembled.
  last.map_log(std::string(text, size - 1));
  write_all(file.path, file.solution.data(), file.solution.size());
  return 0;
}
