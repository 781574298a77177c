// kit-web: kit-render in the browser. Draws one frame of a stage into the page's canvas
// (WebGL2, through the same framework as the desktop's), with kit-render's options:
// the page (tools/web/index.html) turns its URL's ?stage=...&scene=...&view=...&size=WxH
// into --stage/--scene/--view/--size arguments. The canvas shows the image kit-render
// would write for the same options, pixel for pixel: the view is read back and turned
// into 8-bit values as kit-render's PNG writer does, then copied to the canvas.
//
// The page learns how it went through Module.kitDone(state, json): state "ready" or
// "error", json the report (stage, view, size, the GL in use, which extension or
// fallback each feature WebGL2 lacks uses, and the times).
#include <emscripten/emscripten.h>
#include <emscripten/html5.h>

#include <chrono>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "base/error.h"
#include "cli.h"
#include "gl/gl.h"
#include "gl/gl_flavour.h"
#include "gl/pass_clock.h"

namespace {

void report(const char* state, const std::string& json) {
  EM_ASM({ if (Module.kitDone) Module.kitDone(UTF8ToString($0), UTF8ToString($1)); }, state, json.c_str());
}

std::string gl_string(GLenum name) {
  const GLubyte* s = glGetString(name);
  return s ? reinterpret_cast<const char*>(s) : "?";
}

// The page's canvas as a WebGL2 context of exactly width x height pixels: no
// antialiasing (the kit draws into its own targets, and the canvas only receives a
// copy), opaque, and kept after drawing so the page (and the test) can read it back.
EMSCRIPTEN_WEBGL_CONTEXT_HANDLE make_context(int width, int height) {
  if (emscripten_set_canvas_element_size("#canvas", width, height) != EMSCRIPTEN_RESULT_SUCCESS)
    throw kit::Error("the page has no <canvas id=\"canvas\">");
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
  return context;
}

// `image` (rows top-down, 4 float channels) onto the canvas: bytes as kit-render's PNG
// writer makes them (kit::to_unorm8), uploaded and copied 1:1 into the default framebuffer.
void show(const kit::Image& image) {
  const int w = image.width, h = image.height, n = image.channels;
  // Stage 6's precomputed maps have sizes of their own: the canvas takes the image's.
  int canvas_w = 0, canvas_h = 0;
  emscripten_get_canvas_element_size("#canvas", &canvas_w, &canvas_h);
  if (canvas_w != w || canvas_h != h) emscripten_set_canvas_element_size("#canvas", w, h);
  std::vector<unsigned char> rgba(static_cast<size_t>(w) * h * 4, 255);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      // GL's rows run bottom-up: the image's last row is the texture's first.
      const float* from = &image.pixels[(static_cast<size_t>(y) * w + x) * n];
      unsigned char* to = &rgba[(static_cast<size_t>(h - 1 - y) * w + x) * 4];
      for (int c = 0; c < 3; ++c) to[c] = kit::to_unorm8(from[n >= 3 ? c : 0]);
    }
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

}  // namespace

int main(int argc, char** argv) {
  const auto t0 = std::chrono::steady_clock::now();
  nlohmann::json out;
  try {
    kit::CommonOptions options;
    kit::View view = kit::View::Final;
    kit::parse_options(argc, argv, options, [&](const std::string& flag, const kit::OptionValue& value) -> int {
      if (flag == "--view") return view = kit::parse_view(value()), 2;
      return 0;
    });
    const kit::LabSelection lab = kit::select_lab(options);
    const kit::Stage& stage = *lab.stage;
    const kit::RenderSettings& s = options.settings;
    out["stage"] = stage.name;
    out["view"] = kit::view_name(view);
    out["scene"] = options.scene;
    out["size"] = std::to_string(s.width) + "x" + std::to_string(s.height);
    out["shaders"] = lab.root.string();

    kit::Scene scene = kit::load_scene(kit::resolve_scene(options.scene));
    for (const std::string& warning : scene.warnings) std::fprintf(stderr, "kit-web: warning: %s\n", warning.c_str());
    const kit::Camera camera = kit::initial_camera(scene, options);
    const double t_scene = kit::seconds_since(t0);

    make_context(s.width, s.height);
    kit::init_gl_flavour();
    out["gl"] = {{"flavour", kit::gl_flavour_name()}, {"renderer", gl_string(GL_RENDERER)},
                 {"version", gl_string(GL_VERSION)}, {"shading_language", gl_string(GL_SHADING_LANGUAGE_VERSION)}};
    for (const kit::GlFeatureChoice& choice : kit::gl_flavour_report()) out["features"][choice.feature] = choice.used;

    kit::Renderer renderer(stage, kit::stage_library(stage, lab.root), scene, s);
    kit::release_uploaded_data(scene);
    const double t_compile = kit::seconds_since(t0);
    renderer.render(kit::frame_camera(camera, static_cast<float>(s.width) / static_cast<float>(s.height)));
    show(renderer.read_view(view, false));
    glFinish();
    const double t_frame = kit::seconds_since(t0);
    for (const std::string& line : renderer.uniform_warnings()) std::fprintf(stderr, "kit-web: warning: %s\n", line.c_str());
    out["seconds"] = {{"scene", t_scene}, {"compile", t_compile - t_scene}, {"frame", t_frame - t_compile},
                      {"total", t_frame}};
    report("ready", out.dump());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "kit-web: %s\n", e.what());
    out["error"] = e.what();
    report("error", out.dump());
  }
  return 0;
}
