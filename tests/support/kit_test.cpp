#include "kit_test.h"

#include <array>
#include <cmath>
#include <cstdio>
#include <map>

#include "base/error.h"

namespace kit::test {

std::string scene_load_error(const std::filesystem::path& path) {
  try {
    load_scene(path.string());
  } catch (const Error& e) {
    return e.what();
  }
  ADD_FAILURE() << path << " loaded, but a kit::Error was expected";
  return "";
}

void expect_scene_error(const std::filesystem::path& path, const std::string& phrase) {
  const std::string message = scene_load_error(path);
  EXPECT_NE(message.find(path.string()), std::string::npos) << "message does not name the file: " << message;
  EXPECT_NE(message.find(phrase), std::string::npos) << "expected \"" << phrase << "\" in: " << message;
}

RenderSettings small_settings(int width, int height) {
  RenderSettings s;
  s.width = width;
  s.height = height;
  return s;
}

GlContext& context() {
  static std::unique_ptr<GlContext> ctx = create_headless_context(default_headless_backend());
  return *ctx;
}

const Scene& scene(const std::string& name_or_path) {
  static std::map<std::string, std::unique_ptr<Scene>> cache;
  auto it = cache.find(name_or_path);
  if (it == cache.end())
    it = cache.emplace(name_or_path, std::make_unique<Scene>(load_scene(resolve_scene(name_or_path)))).first;
  return *it->second;
}

std::unique_ptr<Renderer> render_stage(const std::string& stage_name, const std::string& scene_name,
                                       RenderSettings settings, const std::filesystem::path& lab_root) {
  context();
  const Stage& stage = find_stage(stage_name);
  const Scene& s = scene(scene_name);
  auto renderer = std::make_unique<Renderer>(stage, stage_library(stage, lab_root), s, settings);
  Camera camera = s.camera ? *s.camera : framing_camera(s);
  renderer->render(frame_camera(camera, static_cast<float>(settings.width) / static_cast<float>(settings.height)));
  glFinish();
  return renderer;
}

std::filesystem::path temp_dir(const std::string& name) {
  std::filesystem::path dir = std::filesystem::path(KIT_BUILD_DIR) / "test-tmp" / name;
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

std::filesystem::path build_dir() { return KIT_BUILD_DIR; }

std::string tool(const std::string& name) { return std::string(KIT_BUILD_DIR) + "/tools/" + name; }

int run(const std::string& command, std::string* output) {
  std::string full = command + " 2>&1";
  FILE* pipe = popen(full.c_str(), "r");
  if (!pipe) return -1;
  std::array<char, 4096> buffer{};
  std::string text;
  size_t n;
  while ((n = fread(buffer.data(), 1, buffer.size(), pipe)) > 0) text.append(buffer.data(), n);
  int status = pclose(pipe);
  if (output) *output = text;
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

float max_abs_difference(const Image& a, const Image& b) {
  if (a.width != b.width || a.height != b.height || a.channels != b.channels) return INFINITY;
  float worst = 0.0f;
  for (size_t i = 0; i < a.pixels.size(); ++i) worst = std::max(worst, std::fabs(a.pixels[i] - b.pixels[i]));
  return worst;
}

}  // namespace kit::test
