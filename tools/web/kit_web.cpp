// kit-web: the kit in a browser tab. The framework's Renderer draws into the page's canvas
// (WebGL2, through the same common/ as the desktop's), and the page (tools/web/page/)
// drives it through one entry point, kit_call(JSON) -> JSON, with commands named in
// dispatch() below: configure, frame, time, camera, reload, lost, restored, check, catalogue.
//
// main() draws the first frame from kit-render's options (the page turns its URL's
// ?stage=...&scene=...&view=...&size=WxH into --stage/--scene/--view/--size arguments) and
// tells the page through Module.kitDone(state, json): state "ready" or "error", json the
// report (stage, view, size, the GL in use, which extension or fallback each feature
// WebGL2 lacks uses, and the times). The canvas then shows the image kit-render would write
// for the same options, pixel for pixel.
#include <emscripten/emscripten.h>
#include <emscripten/html5.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "base/error.h"
#include "camera_rig.h"
#include "cli.h"
#include "gl/gl.h"
#include "gl/gl_flavour.h"
#include "page_check.h"

namespace fs = std::filesystem;

namespace {

using Json = nlohmann::json;

void report(const char* state, const std::string& json) {
  EM_ASM({ if (Module.kitDone) Module.kitDone(UTF8ToString($0), UTF8ToString($1)); }, state, json.c_str());
}

std::string gl_string(GLenum name) {
  const GLubyte* s = glGetString(name);
  return s ? reinterpret_cast<const char*>(s) : "?";
}

// The page's canvas as a WebGL2 context: no antialiasing (the kit draws into its own
// targets, and the canvas only receives a copy), opaque, and kept after drawing so the
// page (and the test) can read it back. The page calls this again after the browser
// restored a lost context: a context made anew enables the extensions again.
EMSCRIPTEN_WEBGL_CONTEXT_HANDLE make_context() {
  EmscriptenWebGLContextAttributes attributes;
  emscripten_webgl_init_context_attributes(&attributes);
  attributes.majorVersion = 2;
  attributes.minorVersion = 0;
  attributes.alpha = EM_FALSE;
  attributes.depth = EM_FALSE;
  attributes.stencil = EM_FALSE;
  attributes.antialias = EM_FALSE;
  attributes.preserveDrawingBuffer = EM_TRUE;
  attributes.enableExtensionsByDefault = EM_TRUE;
  const EMSCRIPTEN_WEBGL_CONTEXT_HANDLE context = emscripten_webgl_create_context("#canvas", &attributes);
  if (context <= 0) throw kit::Error("this browser could not create a WebGL2 context (error " + std::to_string(context) + ")");
  if (emscripten_webgl_make_context_current(context) != EMSCRIPTEN_RESULT_SUCCESS)
    throw kit::Error("the WebGL2 context could not be made current");
  kit::init_gl_flavour();
  return context;
}

// Returns once the GPU has done every command so far. WebGL's glFinish returns at once in
// Chromium; a read of one pixel waits for the commands before it.
void wait_for_gpu() {
  unsigned char pixel[4];
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  glReadPixels(0, 0, 1, 1, GL_RGBA, GL_UNSIGNED_BYTE, pixel);
}

void set_canvas_size(int width, int height) {
  int w = 0, h = 0;
  emscripten_get_canvas_element_size("#canvas", &w, &h);
  if (w != width || h != height) emscripten_set_canvas_element_size("#canvas", width, height);
}

// `image` (rows top-down, float channels) onto the canvas: bytes as kit-render's PNG
// writer makes them (kit::to_unorm8), uploaded and copied 1:1 into the default framebuffer.
// Every view goes this way: a float view cannot be blitted into WebGL's 8-bit canvas, and
// the bytes are then exactly kit-render's.
void show(const kit::Image& image) {
  const int w = image.width, h = image.height;
  // Stage 6's precomputed maps have sizes of their own: the canvas takes the image's.
  set_canvas_size(w, h);
  const std::vector<unsigned char> rgba = kit::web::rgba8(image, true);  // GL's rows run bottom-up
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  const kit::Texture2D texture(w, h, kit::TextureFormat{GL_RGBA8, GL_RGBA, GL_UNSIGNED_BYTE}, rgba.data());
  kit::Framebuffer source;
  source.attach_color(0, texture);
  glBindFramebuffer(GL_READ_FRAMEBUFFER, source.id());
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, 0);
  glBlitFramebuffer(0, 0, w, h, 0, 0, w, h, GL_COLOR_BUFFER_BIT, GL_NEAREST);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  kit::check_gl("showing the frame in the canvas");
}

// What the page is showing: a stage of the labs (or the solutions), a scene, a view and
// the settings kit-view's panel has, at a size.
struct Page {
  std::string stage = "gbuffer", scene = "default", view = "final";
  bool solution = false;
  kit::RenderSettings settings;
  int camera = -1;

  EMSCRIPTEN_WEBGL_CONTEXT_HANDLE context = 0;
  bool lost = false;
  std::optional<kit::Scene> loaded_scene;
  std::string loaded_scene_name;
  std::optional<kit::CameraRig> rig;
  std::unique_ptr<kit::Renderer> renderer;
  std::string renderer_key;  // stage, solution and scene the renderer was built for
  std::string last;          // kit_call's answer, kept until the next call
};

Page& page() {
  static Page p;
  return p;
}

fs::path lab_root(bool solution) { return kit::kit_root() / (solution ? "solutions" : "labs"); }

Json stage_files(const kit::Stage& stage, bool solution) {
  Json files = Json::array();
  for (const std::string& name : stage.files)
    files.push_back({{"name", name}, {"lab", stage.folder}, {"path", (lab_root(solution) / stage.folder / name).string()}});
  return files;
}

// Builds what changed since the last frame: the scene, then the renderer (its shaders).
// Throws kit::Error; the old renderer stays when the new one cannot be built.
void prepare(Page& p) {
  if (p.lost) throw kit::Error("the WebGL context is lost; the page is waiting for the browser to restore it");
  const kit::Stage& stage = kit::find_stage(p.stage);
  if (!p.loaded_scene || p.loaded_scene_name != p.scene) {
    kit::Scene scene = kit::load_scene(kit::resolve_scene(p.scene));
    for (const std::string& warning : scene.warnings) std::fprintf(stderr, "kit-web: warning: %s\n", warning.c_str());
    kit::CommonOptions options;
    options.camera = p.camera;
    p.rig.emplace(scene, kit::initial_camera(scene, options));
    p.loaded_scene = std::move(scene);
    p.loaded_scene_name = p.scene;
    p.renderer.reset();
  }
  const std::string key = p.stage + (p.solution ? "/solution/" : "/labs/") + p.scene;
  if (!p.renderer || p.renderer_key != key) {
    p.renderer = std::make_unique<kit::Renderer>(stage, kit::stage_library(stage, lab_root(p.solution)),
                                                 *p.loaded_scene, p.settings);
    p.renderer_key = key;
  }
  kit::RenderSettings& s = p.renderer->settings();
  if (s.width != p.settings.width || s.height != p.settings.height) p.renderer->resize(p.settings.width, p.settings.height);
  const int width = s.width, height = s.height;
  s = p.settings;
  s.width = width;
  s.height = height;
}

// Draws the current frame into the canvas; the seconds it took, finished (glFinish).
double draw(Page& p) {
  prepare(p);
  const auto t0 = std::chrono::steady_clock::now();
  const kit::RenderSettings& s = p.settings;
  p.renderer->render(kit::frame_camera(p.rig->camera(), static_cast<float>(s.width) / static_cast<float>(s.height)));
  show(p.renderer->read_view(kit::parse_view(p.view), false));
  glFinish();
  return kit::seconds_since(t0);
}

void read_settings(Page& p, const Json& in) {
  kit::RenderSettings& s = p.settings;
  if (in.contains("stage")) p.stage = kit::find_stage(in["stage"].get<std::string>()).name;
  if (in.contains("solution")) p.solution = in["solution"].get<bool>();
  if (in.contains("scene")) p.scene = in["scene"].get<std::string>();
  if (in.contains("view")) p.view = kit::view_name(kit::parse_view(in["view"].get<std::string>()));
  if (in.contains("width")) s.width = std::clamp(in["width"].get<int>(), 16, 4096);
  if (in.contains("height")) s.height = std::clamp(in["height"].get<int>(), 16, 4096);
  if (in.contains("gamma")) s.gamma = in["gamma"].get<float>();
  if (in.contains("attenuation_model")) s.attenuation_model = in["attenuation_model"].get<int>();
  if (in.contains("postprocess")) s.postprocess = in["postprocess"].get<bool>();
  if (in.contains("custom_effect")) s.custom_effect = in["custom_effect"].get<bool>();
  if (in.contains("bloom_threshold")) s.bloom_threshold = in["bloom_threshold"].get<float>();
  if (in.contains("extra_lights")) s.extra_lights = std::clamp(in["extra_lights"].get<int>(), 0, 256);
}

Json describe(const Page& p) {
  const kit::Stage& stage = kit::find_stage(p.stage);
  Json out = {{"stage", stage.name}, {"lab", stage.number}, {"solution", p.solution}, {"scene", p.scene},
              {"view", p.view}, {"size", std::to_string(p.settings.width) + "x" + std::to_string(p.settings.height)},
              {"files", stage_files(stage, p.solution)}};
  out["gl"] = {{"flavour", kit::gl_flavour_name()}, {"renderer", gl_string(GL_RENDERER)},
               {"version", gl_string(GL_VERSION)}, {"shading_language", gl_string(GL_SHADING_LANGUAGE_VERSION)}};
  for (const kit::GlFeatureChoice& choice : kit::gl_flavour_report()) out["features"][choice.feature] = choice.used;
  if (p.renderer)
    for (const std::string& line : p.renderer->uniform_warnings()) out["warnings"].push_back(line);
  return out;
}

// The stages, scenes and views the page offers, and which labs this site has solutions of.
Json catalogue() {
  Json out;
  for (const kit::Stage& stage : kit::stages())
    out["stages"].push_back({{"number", stage.number}, {"name", stage.name}, {"folder", stage.folder},
                             {"files", stage_files(stage, false)},
                             {"solution", fs::is_directory(lab_root(true) / stage.folder)}});
  std::vector<std::string> scenes;
  for (const fs::directory_entry& entry : fs::directory_iterator(kit::scene_dir()))
    if (fs::is_regular_file(entry.path() / (entry.path().filename().string() + ".gltf")))
      scenes.push_back(entry.path().filename().string());
  std::sort(scenes.begin(), scenes.end());
  out["scenes"] = scenes;
  for (const char* view : {"final", "position", "normal", "albedo", "material", "emission", "depth", "hdr", "irradiance",
                           "prefiltered", "brdf-lut"})
    out["views"].push_back(view);
  out["checks"] = kit::web::check_catalogue();
  out["check_scenes"] = kit::web::check_scenes();
  return out;
}

Json dispatch(const Json& in) {
  Page& p = page();
  const std::string cmd = in.value("cmd", std::string());
  if (cmd == "catalogue") return catalogue();
  if (cmd == "configure") {
    read_settings(p, in);
    if (in.contains("camera")) p.camera = in["camera"].get<int>();
    const kit::Renderer* before = p.renderer.get();
    const bool new_scene = !p.loaded_scene || p.loaded_scene_name != p.scene;
    const double seconds = draw(p);
    Json out = describe(p);
    out["seconds"] = seconds;
    out["rebuilt"] = p.renderer.get() != before;  // its shaders compiled anew from the files
    // What the loader left out of a scene it read now (a missing .mtl or texture), as the
    // desktop's tools print it: the page shows it with the student's model.
    if (new_scene) out["scene_warnings"] = p.loaded_scene->warnings;
    return out;
  }
  if (cmd == "frame") return {{"seconds", draw(p)}};
  if (cmd == "time") {
    // Frame times as kit-render --frames --timings measures them: the frame drawn and
    // finished, not shown; the benchmark's per-stage figures (docs/performance.md).
    prepare(p);
    const kit::RenderSettings& s = p.settings;
    Json ms = Json::array();
    for (int i = 0; i < std::clamp(in.value("frames", 10), 1, 1000); ++i) {
      const auto t0 = std::chrono::steady_clock::now();
      p.renderer->render(kit::frame_camera(p.rig->camera(), static_cast<float>(s.width) / static_cast<float>(s.height)));
      wait_for_gpu();
      ms.push_back(1000.0 * kit::seconds_since(t0));
    }
    return {{"frame_ms", ms}};
  }
  if (cmd == "camera") {
    if (!p.rig) throw kit::Error("no scene is loaded");
    const float dx = in.value("dx", 0.0f), dy = in.value("dy", 0.0f);
    const std::string action = in.value("action", std::string());
    if (action == "rotate") p.rig->rotate(dx, dy);
    else if (action == "pan") p.rig->pan(dx, dy);
    else if (action == "zoom") p.rig->zoom(in.value("steps", 0.0f));
    else throw kit::Error("camera: unknown action '" + action + "' (rotate, pan, zoom)");
    return {{"look_at", p.rig->look_at_text()}, {"seconds", draw(p)}};
  }
  if (cmd == "reload") {
    // The page wrote the student's files into the file system: compile them again. A
    // renderer that cannot be built keeps the last good frame on the canvas.
    if (p.renderer) p.renderer->reload_shaders();
    return {{"seconds", draw(p)}};
  }
  if (cmd == "lost") {
    // Every GL object went with the context: the Renderer's names mean nothing now, and
    // deleting them on a lost context does nothing.
    p.lost = true;
    p.renderer.reset();
    return Json::object();
  }
  if (cmd == "restored") {
    if (p.context > 0) emscripten_webgl_destroy_context(p.context);
    p.context = make_context();
    p.lost = false;
    return describe(p);
  }
  if (cmd == "check") {
    if (p.lost) throw kit::Error("the WebGL context is lost; the page is waiting for the browser to restore it");
    // "solution": true checks the site's reference solution of the lab (the test's known answer).
    Json out = kit::web::run_check(in.value("lab", 0), lab_root(in.value("solution", false)), "/check");
    // The check drew into targets of its own; the canvas shows the page's frame again. A lab
    // that does not compile has no frame to show: the check's verdict says why.
    p.renderer.reset();
    try {
      out["seconds_frame"] = draw(p);
    } catch (const std::exception& e) {
      out["frame_error"] = e.what();
    }
    return out;
  }
  throw kit::Error("unknown command '" + cmd + "'");
}

}  // namespace

// The page's entry point: a JSON command in, a JSON answer out, valid until the next call.
// An answer with "error" is a problem to show (with "diagnostics": file, line, message,
// for a shader that does not compile); the last good frame stays on the canvas.
extern "C" EMSCRIPTEN_KEEPALIVE const char* kit_call(const char* json) {
  Page& p = page();
  Json out;
  try {
    out = dispatch(Json::parse(json));
  } catch (const std::exception& e) {
    out = {{"error", e.what()}};
  }
  p.last = out.dump();
  return p.last.c_str();
}

int main(int argc, char** argv) {
  const auto t0 = std::chrono::steady_clock::now();
  Json out;
  try {
    kit::CommonOptions options;
    kit::View view = kit::View::Final;
    kit::parse_options(argc, argv, options, [&](const std::string& flag, const kit::OptionValue& value) -> int {
      if (flag == "--view") return view = kit::parse_view(value()), 2;
      return 0;
    });
    const kit::LabSelection lab = kit::select_lab(options);
    Page& p = page();
    p.stage = lab.stage->name;
    p.solution = options.solution;
    p.scene = options.scene;
    p.view = kit::view_name(view);
    p.camera = options.camera;
    p.settings = options.settings;
    p.context = make_context();
    set_canvas_size(p.settings.width, p.settings.height);
    prepare(p);
    const double t_compile = kit::seconds_since(t0);
    const double frame = draw(p);
    out = describe(p);
    out["shaders"] = lab.root.string();
    out["seconds"] = {{"compile", t_compile}, {"frame", frame}, {"total", kit::seconds_since(t0)}};
    report("ready", out.dump());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "kit-web: %s\n", e.what());
    out["error"] = e.what();
    report("error", out.dump());
  }
  return 0;
}
