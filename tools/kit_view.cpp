// kit-view: a window onto one stage. Renders the stage at the window's
// framebuffer size when something it depends on changed (camera, controls,
// shaders, size), at a lower resolution while the camera moves, shows the final
// image or a G-buffer view, and reloads the stage's shaders when their files
// change (errors are shown, the last good programs keep running).
// `./kit view --lab N [--solution]` opens it.
//   kit-view --stage lighting --shaders labs [--view normal] [--frames N --screenshot out.png]
#include <imgui.h>
#include <imgui_impl_glfw.h>
#include <imgui_impl_opengl3.h>

#include "gl/gl.h"  // glad before GLFW: GLFW_INCLUDE_NONE keeps GLFW's own GL header out
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

#include <glm/gtc/matrix_transform.hpp>

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <iterator>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include "camera_rig.h"
#include "cli.h"
#include "base/error.h"
#include "gl/window.h"
#include "gl/gl_flavour.h"

namespace fs = std::filesystem;

namespace {

constexpr const char* kImGuiGlslVersion = "#version 330 core";
constexpr double kShaderPollSeconds = 0.25;    // how often shader files are checked for changes
constexpr double kTitleRefreshSeconds = 0.25;  // the title shows the frame time, but not every frame
constexpr double kWarningCheckSeconds = 2.0;   // NaN/Inf read-back and uniform check (a read-back costs a few ms)
constexpr double kFrameTimeSmoothing = 0.05;   // weight of the newest frame in the moving average
// While the camera moves, frames are rendered at 1/kMovingResolutionDivisor of the
// window's width and height (a quarter of the pixels: the passes after the geometry
// pass cost per pixel), then scaled up; the first frame the camera holds still is
// rendered at full size, so a still image is always the full-quality one.
constexpr int kMovingResolutionDivisor = 2;
// Frames drawn after the last input before the viewer waits for events again: Dear
// ImGui needs a frame or two to show what a click or a key did.
constexpr int kFramesAfterInput = 3;
constexpr float kSpinPixelsPerFrame = 8.0f;    // --spin: a steady left drag of this many pixels a frame
constexpr double kMaxFlyStepSeconds = 0.1;     // the longest step one frame flies (the loop may have slept)
constexpr float kGammaCycle[] = {2.2f, 1.0f, 0.5f, 2.5f};  // the G key, as in the gamma slides
constexpr float kGammaMin = 0.2f, kGammaMax = 3.0f;
constexpr float kBloomThresholdMax = 5.0f;
constexpr int kMaxViewerLights = 256;
constexpr float kFlyFastFactor = 4.0f;       // with Shift held: the fly speed (camera_rig.h) times this
constexpr float kPanelWidth = 340.0f, kPanelItemWidth = 180.0f;
constexpr float kWindowMargin = 8.0f;           // between the viewport's edges and the panel or messages
constexpr float kMessagesMaxHeightFraction = 0.45f;  // of the viewport: the image stays visible above
const ImVec4 kErrorColor{1.0f, 0.35f, 0.35f, 1.0f};
const ImVec4 kWarningColor{1.0f, 0.8f, 0.3f, 1.0f};
const ImVec4 kNoteColor{0.7f, 0.7f, 0.7f, 1.0f};
// The first stage each setting changes the image in (the panel shows a control from there on).
constexpr int kFirstLitStage = 2;         // extra lights: the lighting pass
constexpr int kFirstDisplayStage = 3;     // gamma and the attenuation model: lab 3's tonemap.glsl and attenuation.glsl
constexpr int kFirstPostprocessStage = 5; // bloom, its threshold and the custom effect

constexpr kit::View kViewKeys[] = {kit::View::Final,    kit::View::Position,   kit::View::Normal,
                                   kit::View::Albedo,   kit::View::Material,   kit::View::Emission,
                                   kit::View::Depth,    kit::View::Hdr,        kit::View::Irradiance,
                                   kit::View::Prefiltered, kit::View::BrdfLut};
// Keys 1-9 pick the first nine views; the rest are in the panel's list only.
constexpr int kViewNumberKeys = 9;
// The prefilter's sample counts the panel offers, as powers of two.
constexpr int kMinPrefilterSamplesLog2 = 4, kMaxPrefilterSamplesLog2 = 11;

struct ViewerOptions {
  kit::CommonOptions common;
  int frames = 0;                 // 0: until the window is closed
  std::string screenshot;         // the stage's final image after the last frame
  std::string window_screenshot;  // the window as shown (view and panel) after the last frame
  kit::View view = kit::View::Final;
  bool hidden = false;
  bool ui = true;
  bool spin = false;     // turn the orbit camera every frame (measures the frame rate while moving)
  bool timings = false;  // print the frame times at exit
};

void usage() {
  std::printf(
      "usage: kit-view --stage NAME [--shaders DIR] [options]\n"
      "Opens a window onto one stage; shaders reload when their files change.\n"
      "  --view VIEW           first view: final (default) | position | normal | albedo | material | emission |\n"
      "                        depth | hdr\n"
      "  --frames N            render N frames, then exit (non-zero if a shader error is still shown)\n"
      "  --screenshot FILE     after the last frame, write the stage's final image (PNG or EXR)\n"
      "  --window-screenshot FILE  after the last frame, write the window as shown, panel included\n"
      "  --hidden              invisible window (the image is still rendered)\n"
      "  --no-ui               no control panel (errors and warnings still go to stderr)\n"
      "  --spin                turn the camera a little every frame, as a steady drag would (with --frames:\n"
      "                        the frame rate while the camera moves; the last frame is still)\n"
      "  --timings             at exit, print how many frames were rendered, at which size, and their median time\n"
      "A frame is rendered only when the camera, a control, a shader or the window size changed (or the\n"
      "custom effect animates); while the camera moves, at half the width and height.\n"
      "Keys: 1-8 view (final, position, normal, albedo, material, emission, depth, hdr),\n"
      "      P postprocess, C custom effect,\n"
      "      G gamma 2.2/1.0/0.5/2.5, A attenuation model (orbit mode), F fly/orbit, F12 or K screenshot,\n"
      "      M light markers, R reload shaders, L print the camera as --look-at (stdout), Esc quit.\n"
      "Mouse: orbit: left drag rotates, wheel zooms, right/middle drag pans;\n"
      "       fly: WASD move, Q/E down/up, Shift faster, right drag looks around.\n"
      "A frame (or a shader build) that takes longer than --timeout ends the viewer with a message on stderr:\n"
      "a GL call that never returns blocks the window too.\n"
      "Shared options (--size sets the window size; --backend is not used, the window is the context):\n%s",
      kit::common_options_help());
}

int parse_frame_count(const std::string& text) {
  if (const std::optional<long> n = kit::parse_whole_number(text, 1, std::numeric_limits<int>::max()))
    return static_cast<int>(*n);
  throw kit::Error("--frames expects a whole number of at least 1 (got '" + text + "')");
}


void delete_query(GLuint id) { glDeleteQueries(1, &id); }

// GPU time of a frame's render and display, read a frame later so reading never stalls.
class GpuTimer {
 public:
  GpuTimer() {
    for (auto& q : queries_) {
      GLuint id = 0;
      glGenQueries(1, &id);
      q = kit::GlName<delete_query>(id);
    }
  }
  void begin() {
    const auto& q = queries_[static_cast<size_t>(frame_ % 2)];
    if (frame_ >= 2 && kit::time_elapsed_ready(q.get()))
      milliseconds_ = static_cast<double>(kit::time_elapsed_ns(q.get())) * 1e-6;
    kit::begin_time_elapsed(q.get());
  }
  void end() {
    kit::end_time_elapsed();
    ++frame_;
  }
  double milliseconds() const { return milliseconds_; }

 private:
  kit::GlName<delete_query> queries_[2];
  long frame_ = 0;
  double milliseconds_ = 0.0;
};

// Dear ImGui's context and its GLFW and OpenGL 3 backends, for one window.
class ImGuiSession {
 public:
  explicit ImGuiSession(GLFWwindow* window) {
    IMGUI_CHECKVERSION();
    ImGui::CreateContext();
    ImGui::GetIO().IniFilename = nullptr;  // no imgui.ini left in the student's folder
    ImGui::StyleColorsDark();
    // Installs its callbacks after the viewer's and calls those first.
    ImGui_ImplGlfw_InitForOpenGL(window, true);
    ImGui_ImplOpenGL3_Init(kImGuiGlslVersion);
  }
  ~ImGuiSession() {
    ImGui_ImplOpenGL3_Shutdown();
    ImGui_ImplGlfw_Shutdown();
    ImGui::DestroyContext();
  }
  ImGuiSession(const ImGuiSession&) = delete;
  ImGuiSession& operator=(const ImGuiSession&) = delete;
};

class Viewer {
 public:
  explicit Viewer(ViewerOptions options)
      : options_(std::move(options)),
        settings_(options_.common.settings),
        lab_(kit::select_lab(options_.common)),
        stage_(lab_.stage),
        shader_root_(lab_.root),
        watchdog_("kit-view", options_.common.timeout,
                  "The window cannot show this while the GL call runs: fix the shader, then open the viewer again."),
        scene_(kit::load_scene(kit::resolve_scene(options_.common.scene))),
        window_(settings_.width, settings_.height, title_prefix(), !options_.hidden),
        rig_(scene_, kit::initial_camera(scene_, options_.common)),
        view_(options_.view) {
    for (const std::string& warning : scene_.warnings) std::fprintf(stderr, "kit-view: warning: %s\n", warning.c_str());
    kit::note_default_light_rig("kit-view", scene_, *stage_, settings_);
    if (settings_.extra_lights > kMaxViewerLights) {
      std::fprintf(stderr, "kit-view: note: --lights %d is more than the viewer's slider holds; using %d\n",
                   settings_.extra_lights, kMaxViewerLights);
      settings_.extra_lights = kMaxViewerLights;
    }
    GLFWwindow* handle = window_.handle();
    glfwSetWindowUserPointer(handle, this);
    glfwSetKeyCallback(handle, on_key);
    glfwSetScrollCallback(handle, on_scroll);
    glfwSetCursorPosCallback(handle, on_cursor);
    glfwSetMouseButtonCallback(handle, on_mouse_button);
    glfwSetCharCallback(handle, on_char);
    glfwSetWindowSizeCallback(handle, on_window_size);
    glfwGetCursorPos(handle, &cursor_x_, &cursor_y_);
    if (options_.ui) imgui_ = std::make_unique<ImGuiSession>(handle);

    int width = 0, height = 0;
    window_.framebuffer_size(&width, &height);
    if (width != settings_.width || height != settings_.height)
      std::fprintf(stderr, "kit-view: note: the window's framebuffer is %dx%d, not the requested %dx%d "
                   "(display scaling or the window manager changed it); images are %dx%d\n",
                   width, height, settings_.width, settings_.height, width, height);
    settings_.width = std::max(width, 1);
    settings_.height = std::max(height, 1);
    build_renderer();
    select_view(view_);
  }

  int run() {
    const double start = glfwGetTime();
    double last = start, next_poll = start, next_title = start, next_check = start;
    int frame = 0;
    bool draw_next = true;  // the last frame rendered, or input came: draw the next one without waiting
    while (!window_.should_close()) {
      // Nothing to redraw: sleep until an event or the next shader poll (--frames never waits).
      if (options_.frames == 0 && !draw_next) glfwWaitEventsTimeout(kShaderPollSeconds);
      else glfwPollEvents();
      double now = glfwGetTime();
      const double frame_start = now;
      double seconds = now - last;
      last = now;
      if (now >= next_poll) {
        poll_shader_files();
        next_poll = now + kShaderPollSeconds;
      }
      bool last_frame = options_.frames > 0 && frame + 1 >= options_.frames;
      if (options_.spin && !last_frame) left_drag_.x += kSpinPixelsPerFrame;
      // A wait for events is not flying time: a held key moves by one frame's step at most.
      move_camera(static_cast<float>(std::min(seconds, kMaxFlyStepSeconds)));
      settings_.time = static_cast<float>(now - start);

      int width = 0, height = 0;
      window_.framebuffer_size(&width, &height);
      if (width == 0 || height == 0) {  // minimised: nothing to draw into
        glfwWaitEvents();
        continue;
      }
      // Everything up to the swap runs under the time limit: a shader that never
      // finishes blocks whichever GL call waits for it first.
      in_frame_ = true;
      watchdog_.arm(frame_activity());
      // A screenshot and --frames' last frame are full-quality images.
      const Rendered rendered = draw_frame(width, height, last_frame || screenshot_requested_);
      // Warnings count a full-size frame's pixels, so their numbers do not flicker while moving.
      if (rendered == Rendered::Full && (warnings_due_ || now >= next_check)) {
        refresh_warnings();
        next_check = now + kWarningCheckSeconds;
      }
      if (imgui_) draw_ui();

      if (screenshot_requested_) write_key_screenshot();
      if (last_frame) write_final_screenshots();
      window_.swap_buffers();
      watchdog_.disarm();
      in_frame_ = false;
      if (rendered != Rendered::None) note_frame_time(rendered, (glfwGetTime() - frame_start) * 1000.0);
      if (now >= next_title) {
        refresh_title();
        next_title = now + kTitleRefreshSeconds;
      }
      if (input_frames_left_ > 0) --input_frames_left_;
      draw_next = rendered != Rendered::None || input_frames_left_ > 0 || animated();
      ++frame;
      if (last_frame) break;
    }
    if (options_.timings) print_timings(frame);
    // With --frames the viewer is a check: a shader error still showing is a failure.
    return options_.frames > 0 && !error_.empty() ? 1 : 0;
  }

 private:
  // ---- GLFW callbacks: the viewer is reached through the window's user pointer.
  static Viewer& from(GLFWwindow* window) { return *static_cast<Viewer*>(glfwGetWindowUserPointer(window)); }
  // Every callback counts as input: the next frames are drawn (kFramesAfterInput).
  static Viewer& input(GLFWwindow* window) {
    Viewer& v = from(window);
    v.input_frames_left_ = kFramesAfterInput;
    return v;
  }
  static void on_key(GLFWwindow* window, int key, int, int action, int) { input(window).key(key, action); }
  static void on_cursor(GLFWwindow* window, double x, double y) { input(window).cursor_moved(x, y); }
  static void on_scroll(GLFWwindow* window, double, double dy) {
    Viewer& v = input(window);
    if (!v.ui_wants_mouse()) v.wheel_steps_ += static_cast<float>(dy);
  }
  static void on_mouse_button(GLFWwindow* window, int, int, int) { input(window); }
  static void on_char(GLFWwindow* window, unsigned int) { input(window); }
  static void on_window_size(GLFWwindow* window, int, int) { input(window); }

  bool ui_wants_mouse() const { return imgui_ && ImGui::GetIO().WantCaptureMouse; }
  bool ui_wants_keyboard() const { return imgui_ && ImGui::GetIO().WantCaptureKeyboard; }

  void key(int key, int action) {
    if (action != GLFW_PRESS) return;
    if (key == GLFW_KEY_ESCAPE) {
      glfwSetWindowShouldClose(window_.handle(), GLFW_TRUE);
      return;
    }
    if (ui_wants_keyboard()) return;
    if (key >= GLFW_KEY_1 && key < GLFW_KEY_1 + std::min(kViewNumberKeys, static_cast<int>(std::size(kViewKeys)))) {
      select_view(kViewKeys[key - GLFW_KEY_1]);
      return;
    }
    switch (key) {
      case GLFW_KEY_P:
        if (applies(kFirstPostprocessStage, "postprocess (P)")) settings_.postprocess = !settings_.postprocess;
        break;
      case GLFW_KEY_C:
        if (applies(kFirstPostprocessStage, "the custom effect (C)")) settings_.custom_effect = !settings_.custom_effect;
        break;
      case GLFW_KEY_G:
        if (applies(kFirstDisplayStage, "gamma (G)")) cycle_gamma();
        break;
      case GLFW_KEY_A:  // in fly mode A strafes left; the panel still switches the model
        if (!rig_.flying() && applies(kFirstDisplayStage, "the attenuation model (A)"))
          settings_.attenuation_model = 1 - settings_.attenuation_model;
        break;
      case GLFW_KEY_M:
        if (applies(kFirstLitStage, "light markers (M)")) settings_.light_markers = !settings_.light_markers;
        break;
      case GLFW_KEY_F: rig_.toggle_fly(); break;
      case GLFW_KEY_F12:
      case GLFW_KEY_K: screenshot_requested_ = true; break;
      case GLFW_KEY_R: reload_now(); break;
      case GLFW_KEY_L: set_note("camera: --look-at " + rig_.look_at_text()); break;
      default: break;
    }
  }

  // Whether a setting first used by stage `first` changes the current stage's image; says so when not.
  bool applies(int first, const char* what) {
    if (stage_->number >= first) return true;
    set_note(std::string(what) + " changes nothing before stage " + std::to_string(first) + " (" +
             kit::stages()[static_cast<size_t>(first - 1)].name + ")");
    return false;
  }

  void cycle_gamma() {
    // The next preset after the one nearest the current gamma (the slider may sit between them).
    size_t nearest = 0;
    for (size_t i = 1; i < std::size(kGammaCycle); ++i)
      if (std::abs(kGammaCycle[i] - settings_.gamma) < std::abs(kGammaCycle[nearest] - settings_.gamma)) nearest = i;
    settings_.gamma = kGammaCycle[(nearest + 1) % std::size(kGammaCycle)];
  }

  void select_view(kit::View view) {
    if (view == kit::View::Hdr && !stage_->lighting) {
      set_note("view hdr needs a lit stage (lighting or later); showing final");
      view = kit::View::Final;
    }
    if (kit::is_precomputed_map(view) && !stage_->ibl) {
      set_note(std::string("view ") + kit::view_name(view) + " needs stage 6 (ibl); showing final");
      view = kit::View::Final;
    }
    view_ = view;
  }

  // Drags are summed per button as GLFW reports the motion, so a move is
  // counted with the buttons held at that moment, not at the next frame.
  void cursor_moved(double x, double y) {
    glm::vec2 delta(static_cast<float>(x - cursor_x_), static_cast<float>(y - cursor_y_));
    cursor_x_ = x;
    cursor_y_ = y;
    if (ui_wants_mouse()) return;
    GLFWwindow* w = window_.handle();
    if (glfwGetMouseButton(w, GLFW_MOUSE_BUTTON_LEFT) == GLFW_PRESS) left_drag_ += delta;
    if (glfwGetMouseButton(w, GLFW_MOUSE_BUTTON_RIGHT) == GLFW_PRESS) right_drag_ += delta;
    if (glfwGetMouseButton(w, GLFW_MOUSE_BUTTON_MIDDLE) == GLFW_PRESS) middle_drag_ += delta;
  }

  void move_camera(float seconds) {
    constexpr glm::vec2 kNone(0.0f);
    if (rig_.flying()) {
      if (right_drag_ != kNone) rig_.look(right_drag_.x, right_drag_.y);
      if (!ui_wants_keyboard()) {
        GLFWwindow* w = window_.handle();
        auto axis = [&](int plus, int minus) {
          return (glfwGetKey(w, plus) == GLFW_PRESS ? 1.0f : 0.0f) - (glfwGetKey(w, minus) == GLFW_PRESS ? 1.0f : 0.0f);
        };
        glm::vec3 move(axis(GLFW_KEY_D, GLFW_KEY_A), axis(GLFW_KEY_E, GLFW_KEY_Q), axis(GLFW_KEY_W, GLFW_KEY_S));
        if (glfwGetKey(w, GLFW_KEY_LEFT_SHIFT) == GLFW_PRESS) move *= kFlyFastFactor;
        if (move != glm::vec3(0.0f)) {
          rig_.fly(move, seconds);
          input_frames_left_ = kFramesAfterInput;  // a held key sends no events to wake the loop
        }
      }
    } else {
      if (left_drag_ != kNone) rig_.rotate(left_drag_.x, left_drag_.y);
      glm::vec2 pan = right_drag_ + middle_drag_;
      if (pan != kNone) rig_.pan(pan.x, pan.y);
    }
    left_drag_ = right_drag_ = middle_drag_ = kNone;
    if (wheel_steps_ != 0.0f) {
      rig_.zoom(wheel_steps_);
      wheel_steps_ = 0.0f;
    }
  }

  // ---- Rendering and display.
  // What a rendered frame depends on. When all of it is as it was for the last
  // rendered frame, the viewer shows that frame again instead of rendering it anew.
  // The view is not in it: G-buffer views are drawn from the last frame's G-buffer.
  struct FrameInputs {
    kit::FrameCamera camera;
    kit::RenderSettings settings;  // its size is the window's; the size rendered at is below
    int width = 0, height = 0;
    long shader_builds = 0;
  };
  static bool same_frame(const FrameInputs& a, const FrameInputs& b) {
    return kit::same_frame_camera(a.camera, b.camera) && kit::same_image_settings(a.settings, b.settings) &&
           a.width == b.width && a.height == b.height && a.shader_builds == b.shader_builds;
  }
  // The custom effect may animate with u_time: it is rendered every frame.
  bool animated() const { return renderer_ && settings_.custom_effect && renderer_->stage().postprocess; }

  enum class Rendered { None, Moving, Full };

  // Renders the stage if what it depends on changed: at the window's size, or at
  // 1/kMovingResolutionDivisor of it while the camera moves (unless `full_quality`);
  // then shows the current view.
  Rendered draw_frame(int width, int height, bool full_quality) {
    // A failed shader build can leave its deleted program current; Dear ImGui
    // would restore it after drawing the panel (GL_INVALID_VALUE).
    glUseProgram(0);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glViewport(0, 0, width, height);
    glClearColor(0.0f, 0.0f, 0.0f, 1.0f);
    glClear(GL_COLOR_BUFFER_BIT);
    if (!renderer_) return Rendered::None;  // the stage never compiled: the panel shows why
    Rendered rendered = Rendered::None;
    gpu_timer_->begin();
    try {
      FrameInputs inputs;
      inputs.camera = kit::frame_camera(rig_.camera(), static_cast<float>(width) / static_cast<float>(height));
      inputs.settings = settings_;
      inputs.shader_builds = shader_builds_;
      const bool moving =
          !full_quality && last_frame_inputs_ && !kit::same_frame_camera(inputs.camera, last_frame_inputs_->camera);
      const int divisor = moving ? kMovingResolutionDivisor : 1;
      inputs.width = std::max(width / divisor, 1);
      inputs.height = std::max(height / divisor, 1);
      if (animated() || !last_frame_inputs_ || !same_frame(inputs, *last_frame_inputs_)) {
        // The renderer keeps its own size (resize reallocates the targets); everything else follows the controls.
        kit::RenderSettings& s = renderer_->settings();
        int rendered_width = s.width, rendered_height = s.height;
        s = settings_;
        s.width = rendered_width;
        s.height = rendered_height;
        last_frame_inputs_.reset();  // a frame that throws is rendered again next time
        renderer_->resize(inputs.width, inputs.height);
        renderer_->render(inputs.camera);
        last_frame_inputs_ = inputs;
        rendered = moving ? Rendered::Moving : Rendered::Full;
      }
      show(renderer_->display_texture(view_), width, height);
    } catch (const kit::Error& e) {
      report_error(e.what());
    }
    gpu_timer_->end();
    return rendered;
  }

  // Copies a texture to the window; blitting converts float views to the window's 8 bits.
  // A frame rendered smaller while moving is scaled up bilinearly; the precomputed maps
  // are shown texel by texel.
  void show(const kit::Texture2D& texture, int width, int height) {
    const bool smooth = (texture.width() != width || texture.height() != height) && !kit::is_precomputed_map(view_);
    blit_source_->attach_color(0, texture);
    glBindFramebuffer(GL_READ_FRAMEBUFFER, blit_source_->id());
    glReadBuffer(GL_COLOR_ATTACHMENT0);
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, 0);
    glBlitFramebuffer(0, 0, texture.width(), texture.height(), 0, 0, width, height, GL_COLOR_BUFFER_BIT,
                      smooth ? GL_LINEAR : GL_NEAREST);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    kit::check_gl("showing the view");
  }

  // The back buffer as drawn this frame (view and panel), through a texture so
  // kit::read_texture does the read-back.
  kit::Image window_image() {
    int width = 0, height = 0;
    window_.framebuffer_size(&width, &height);
    kit::Texture2D copy(width, height, {GL_RGBA8, GL_RGBA, GL_UNSIGNED_BYTE});
    kit::Framebuffer target;
    target.attach_color(0, copy);
    glBindFramebuffer(GL_READ_FRAMEBUFFER, 0);
    glReadBuffer(GL_BACK);
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, target.id());
    glBlitFramebuffer(0, 0, width, height, 0, 0, width, height, GL_COLOR_BUFFER_BIT, GL_NEAREST);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    return kit::read_texture(copy);
  }

  void write_final_screenshots() {
    if (!options_.screenshot.empty()) {
      if (renderer_) save_image(options_.screenshot, [&] { return renderer_->read_view(kit::View::Final, false); });
      else report_error("no screenshot written: the stage did not build");
    }
    if (!options_.window_screenshot.empty()) save_image(options_.window_screenshot, [&] { return window_image(); });
  }

  void write_key_screenshot() {
    screenshot_requested_ = false;
    if (!renderer_) {
      set_note("no screenshot: the stage did not build");
      return;
    }
    fs::path folder = kit::kit_root() / "out" / "screenshots";
    std::error_code ec;
    fs::create_directories(folder, ec);
    fs::path path;
    for (int n = 1;; ++n) {  // never overwrite an earlier screenshot
      path = folder / (stage_->name + "-" + std::to_string(n) + ".png");
      if (!fs::exists(path, ec)) break;
    }
    save_image(path.string(), [&] { return renderer_->read_view(view_, false); });
  }

  template <class MakeImage>
  bool save_image(const std::string& path, MakeImage make_image) {
    try {
      kit::write_image(path, make_image());
      set_note("wrote " + path);
      return true;
    } catch (const kit::Error& e) {
      report_error(e.what());
      return false;
    }
  }

  // ---- Shaders: building, hot reload, errors.
  // Shader builds run under the time limit as well; inside a frame, the frame's
  // limit starts again once the build is done.
  class TimedWork {
   public:
    TimedWork(Viewer& viewer, const std::string& activity) : viewer_(viewer) { viewer_.watchdog_.arm(activity); }
    ~TimedWork() {
      if (viewer_.in_frame_) viewer_.watchdog_.arm(viewer_.frame_activity());
      else viewer_.watchdog_.disarm();
    }
    TimedWork(const TimedWork&) = delete;
    TimedWork& operator=(const TimedWork&) = delete;

   private:
    Viewer& viewer_;
  };

  std::string frame_activity() const {
    return "rendering stage " + (renderer_ ? renderer_->stage().name : stage_->name);
  }

  void build_renderer() {
    TimedWork timed(*this, "compiling the shaders of stage " + stage_->name);
    try {
      kit::check_lab_folder(options_.common, shader_root_, *stage_);
      auto renderer = std::make_unique<kit::Renderer>(*stage_, kit::stage_library(*stage_, shader_root_), scene_, settings_);
      bool retry = !error_.empty();
      renderer_ = std::move(renderer);  // replaces the old stage only once the new one built
      ++shader_builds_;
      if (retry) set_note("stage " + stage_->name + " built");
      if (!gpu_timer_) gpu_timer_ = std::make_unique<GpuTimer>();
      if (!blit_source_) blit_source_ = std::make_unique<kit::Framebuffer>();
      error_.clear();
      warnings_due_ = true;
    } catch (const kit::Error& e) {
      report_error(e.what());
    }
  }

  void switch_stage(const kit::Stage& stage) {
    stage_ = &stage;
    select_view(view_);
    build_renderer();
    watched_.clear();  // other files now; the next poll takes their times
    refresh_title();
  }

  bool stage_is_built() const { return renderer_ && renderer_->stage().number == stage_->number; }

  void reload() {
    if (!stage_is_built()) {
      build_renderer();
      return;
    }
    TimedWork timed(*this, "compiling the shaders of stage " + stage_->name);
    try {
      renderer_->reload_shaders();
      ++shader_builds_;
      error_.clear();
      warnings_due_ = true;
      set_note("shaders reloaded");
    } catch (const kit::Error& e) {
      report_error(e.what());  // the old programs keep running
    }
  }

  void reload_now() {  // the R key and the button; the next poll starts from the files as they are then
    reload();
    watched_.clear();
  }

  // The files the stage is made of; while it does not build, every file in its
  // shader folders (a missing file may be about to appear).
  std::vector<fs::path> shader_files() const {
    if (stage_is_built()) return renderer_->shader_paths();
    std::vector<fs::path> files;
    const kit::ShaderLibrary library = kit::stage_library(*stage_, shader_root_);
    for (const kit::ShaderFolder& folder : library.folders()) {
      files.push_back(folder.path);  // its time changes when a file is added or removed
      std::error_code ec;
      for (fs::directory_iterator it(folder.path, ec), end; !ec && it != end; it.increment(ec)) files.push_back(it->path());
    }
    return files;
  }

  using FileTimes = std::map<fs::path, fs::file_time_type>;

  FileTimes file_times() const {
    FileTimes times;
    for (const fs::path& path : shader_files()) {
      std::error_code ec;
      times[path] = fs::last_write_time(path, ec);  // a missing file reads as an error time, also a change
    }
    return times;
  }

  void poll_shader_files() {
    FileTimes times = file_times();
    if (watched_.empty() || times == watched_) {
      watched_ = std::move(times);
      return;
    }
    reload();
    // Keep the times from before the rebuild when the same files are watched,
    // so an edit saved while it compiled still counts at the next poll.
    FileTimes after = file_times();
    bool same_files = std::equal(after.begin(), after.end(), times.begin(), times.end(),
                                 [](const auto& a, const auto& b) { return a.first == b.first; });
    watched_ = same_files ? std::move(times) : std::move(after);
  }

  // NaN/Inf pixels and uniforms nothing sets, as kit-render and the grader report
  // them; printed once when they change, shown under the image.
  void refresh_warnings() {
    warnings_due_ = false;
    std::vector<std::string> found;
    try {
      for (const kit::NonFiniteCount& n : renderer_->non_finite_pixels())
        if (n.pixels > 0)
          found.push_back(std::to_string(n.pixels) + " of " + std::to_string(n.of) + " pixels of the " + kit::view_name(n.view) +
                          " view are NaN or Inf: " + kit::kNonFiniteAdvice);
      for (const std::string& line : renderer_->uniform_warnings()) found.push_back(line);
    } catch (const kit::Error& e) {
      report_error(e.what());
      return;
    }
    if (found == warnings_) return;
    for (const std::string& line : found)
      if (std::find(warnings_.begin(), warnings_.end(), line) == warnings_.end())
        std::fprintf(stderr, "kit-view: warning: %s\n", line.c_str());
    warnings_ = std::move(found);
  }

  void set_note(const std::string& message) {
    std::printf("kit-view: %s\n", message.c_str());
    std::fflush(stdout);  // in order with the errors on stderr when both go to one log
    note_ = message;
  }

  void report_error(const std::string& message) {
    if (message != error_) std::fprintf(stderr, "kit-view: %s\n", message.c_str());
    error_ = message;
  }

  // ---- Frame times: of the frames that rendered, from the end of the event wait to after the swap.
  void note_frame_time(Rendered rendered, double ms) {
    frame_ms_ = frame_times_[0].empty() && frame_times_[1].empty() ? ms : frame_ms_ + kFrameTimeSmoothing * (ms - frame_ms_);
    const int kind = rendered == Rendered::Moving ? 0 : 1;
    frame_times_[kind].push_back(ms);
    if (last_frame_inputs_) frame_sizes_[kind] = {last_frame_inputs_->width, last_frame_inputs_->height};
  }

  // --timings: how many frames rendered, at which size, and their median times.
  void print_timings(int frames) const {
    const size_t moving = frame_times_[0].size(), full = frame_times_[1].size();
    std::printf("kit-view: timings: %d frames, %zu rendered (%zu while moving at %dx%d, %zu still at %dx%d), %zu shown again\n",
                frames, moving + full, moving, frame_sizes_[0].x, frame_sizes_[0].y, full, frame_sizes_[1].x,
                frame_sizes_[1].y, static_cast<size_t>(frames) - moving - full);
    const char* names[] = {"moving", "still"};
    for (int i = 0; i < 2; ++i) {
      if (frame_times_[i].empty()) continue;
      std::vector<double> times = frame_times_[i];
      std::nth_element(times.begin(), times.begin() + static_cast<long>(times.size() / 2), times.end());
      const double median = times[times.size() / 2];
      std::printf("kit-view: timings: %s frames: median %.1f ms (%.1f fps)\n", names[i], median, 1000.0 / median);
    }
    std::fflush(stdout);
  }

  // ---- Window title and control panel.
  std::string title_prefix() const { return "kit-view: " + std::to_string(stage_->number) + " " + stage_->name; }

  void refresh_title() {
    char text[256];
    std::snprintf(text, sizeof text, "%s [%s]  %.1f ms%s", title_prefix().c_str(), kit::view_name(view_), frame_ms_,
                  error_.empty() ? "" : "  (shader error)");
    glfwSetWindowTitle(window_.handle(), text);
  }

  void draw_ui() {
    ImGui_ImplOpenGL3_NewFrame();
    ImGui_ImplGlfw_NewFrame();
    ImGui::NewFrame();
    float messages_height = draw_messages();
    draw_panel(messages_height);
    ImGui::Render();
    ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
  }

  // The shader error and the warnings, in a window across the bottom of the
  // viewport: wrapped to its width, never taller than kMessagesMaxHeightFraction
  // of it (it scrolls), so they show at any window size. Returns its height.
  float draw_messages() {
    if (error_.empty() && warnings_.empty()) return 0.0f;
    const ImVec2 display = ImGui::GetIO().DisplaySize;
    const float width = std::max(display.x - 2.0f * kWindowMargin, 1.0f);
    const float max_height = std::max(display.y * kMessagesMaxHeightFraction, 1.0f);
    ImGui::SetNextWindowPos(ImVec2(kWindowMargin, display.y - kWindowMargin), ImGuiCond_Always, ImVec2(0.0f, 1.0f));
    ImGui::SetNextWindowSizeConstraints(ImVec2(width, 0.0f), ImVec2(width, max_height));
    ImGui::SetNextWindowBgAlpha(0.85f);
    const ImGuiWindowFlags flags = ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoResize | ImGuiWindowFlags_NoCollapse |
                                   ImGuiWindowFlags_NoSavedSettings | ImGuiWindowFlags_AlwaysAutoResize;
    std::string title = error_.empty() ? "warnings" : "shader error";
    if (!error_.empty()) title += renderer_ ? ": the last shaders that built keep running" : ": nothing to show until it builds";
    ImGui::Begin((title + "###messages").c_str(), nullptr, flags);
    ImGui::PushTextWrapPos(0.0f);
    if (!error_.empty()) {
      ImGui::PushStyleColor(ImGuiCol_Text, kErrorColor);
      ImGui::TextUnformatted(error_.c_str());
      ImGui::PopStyleColor();
      ImGui::TextColored(kNoteColor, "saving a shader file (or R) tries again");
    }
    for (const std::string& warning : warnings_) {
      ImGui::PushStyleColor(ImGuiCol_Text, kWarningColor);
      ImGui::TextUnformatted(("warning: " + warning).c_str());
      ImGui::PopStyleColor();
    }
    ImGui::PopTextWrapPos();
    float height = ImGui::GetWindowSize().y;
    ImGui::End();
    return height;
  }

  // The controls, top left, above the messages. Only what changes the current
  // stage's image is shown: lights from stage 2, gamma and the attenuation
  // model from stage 3, bloom and the custom effect in stage 5.
  void draw_panel(float messages_height) {
    const ImVec2 display = ImGui::GetIO().DisplaySize;
    float room = display.y - 2.0f * kWindowMargin - (messages_height > 0.0f ? messages_height + kWindowMargin : 0.0f);
    ImGui::SetNextWindowPos(ImVec2(kWindowMargin, kWindowMargin), ImGuiCond_FirstUseEver);
    ImGui::SetNextWindowSize(ImVec2(kPanelWidth, 0), ImGuiCond_FirstUseEver);
    ImGui::SetNextWindowSizeConstraints(ImVec2(0.0f, 0.0f), ImVec2(FLT_MAX, std::max(room, ImGui::GetFrameHeight())));
    ImGui::Begin("kit-view");
    ImGui::PushItemWidth(kPanelItemWidth);  // leaves room for the labels on the right
    ImGui::Text("frame %.2f ms (%.0f fps), GPU %.2f ms", frame_ms_, frame_ms_ > 0.0 ? 1000.0 / frame_ms_ : 0.0,
                gpu_timer_ ? gpu_timer_->milliseconds() : 0.0);

    std::string current = std::to_string(stage_->number) + " " + stage_->name;
    if (ImGui::BeginCombo("stage", current.c_str())) {
      for (const kit::Stage& s : kit::stages()) {
        std::string label = std::to_string(s.number) + " " + s.name;
        if (ImGui::Selectable(label.c_str(), &s == stage_) && &s != stage_) switch_stage(s);
      }
      ImGui::EndCombo();
    }
    if (renderer_ && !stage_is_built())
      ImGui::TextColored(kNoteColor, "showing %s until %s builds", renderer_->stage().name.c_str(), stage_->name.c_str());

    if (ImGui::BeginCombo("view", kit::view_name(view_))) {
      for (size_t i = 0; i < std::size(kViewKeys); ++i) {
        kit::View v = kViewKeys[i];
        if ((v == kit::View::Hdr && !stage_->lighting) || (kit::is_precomputed_map(v) && !stage_->ibl)) continue;
        std::string label = (static_cast<int>(i) < kViewNumberKeys ? std::to_string(i + 1) + " " : std::string("  ")) +
                            kit::view_name(v);
        if (ImGui::Selectable(label.c_str(), v == view_)) select_view(v);
      }
      ImGui::EndCombo();
    }

    const int stage = stage_->number;
    if (stage >= kFirstPostprocessStage) {
      ImGui::Checkbox("postprocess (P)", &settings_.postprocess);
      ImGui::Checkbox("custom effect (C)", &settings_.custom_effect);
      ImGui::BeginDisabled(!settings_.postprocess);
      ImGui::SliderFloat("bloom threshold", &settings_.bloom_threshold, 0.0f, kBloomThresholdMax);
      ImGui::EndDisabled();
    }
    if (stage >= kFirstDisplayStage) {
      ImGui::SliderFloat("gamma (G)", &settings_.gamma, kGammaMin, kGammaMax, "%.2f");
      ImGui::TextUnformatted("attenuation (A)");
      ImGui::SameLine();
      ImGui::RadioButton("physical", &settings_.attenuation_model, 0);
      ImGui::SameLine();
      ImGui::RadioButton("simple", &settings_.attenuation_model, 1);
    }
    if (stage >= kFirstLitStage) {
      ImGui::SliderInt("extra lights", &settings_.extra_lights, 0, kMaxViewerLights);
      ImGui::Checkbox("light markers (M)", &settings_.light_markers);
    }
    if (stage_->ibl) {
      const std::string shown = kit::environment_or_default(settings_.environment);
      if (ImGui::BeginCombo("environment", shown.c_str())) {
        for (const std::string& name : kit::kit_environment_names())
          if (ImGui::Selectable(name.c_str(), name == shown)) settings_.environment = name;
        ImGui::EndCombo();
      }
      // Powers of two, so the Hammersley points stay evenly spread.
      int samples_log2 = static_cast<int>(std::lround(std::log2(std::max(settings_.ibl.prefilter_samples, 1))));
      if (ImGui::SliderInt("prefilter samples", &samples_log2, kMinPrefilterSamplesLog2, kMaxPrefilterSamplesLog2,
                           std::to_string(1 << samples_log2).c_str()))
        settings_.ibl.prefilter_samples = 1 << samples_log2;
      if (const kit::ImageBasedLighting* ibl = renderer_ ? std::as_const(*renderer_).image_based_lighting() : nullptr)
        ImGui::Text("maps precomputed in %.0f ms", 1000.0 * ibl->precompute_seconds());
    }
    ImGui::TextWrapped("camera (F): %s", rig_.flying() ? "fly: WASD, Q/E down/up, right drag looks"
                                                         : "orbit: left drag turns, wheel zooms, right drag pans");
    if (ImGui::Button("reload shaders (R)")) reload_now();
    ImGui::SameLine();
    if (ImGui::Button("screenshot (K)")) screenshot_requested_ = true;
    if (!note_.empty()) ImGui::TextColored(kNoteColor, "%s", note_.c_str());
    if (!error_.empty()) ImGui::TextColored(kErrorColor, "shader error: see below");
    ImGui::PopItemWidth();
    ImGui::End();
  }

  // Members in construction order: the window (and its GL context) outlives everything that uses GL.
  ViewerOptions options_;
  kit::RenderSettings settings_;  // what the controls set; copied into the renderer each frame
  kit::LabSelection lab_;         // the stage and lab folders the command line asked for
  const kit::Stage* stage_;       // the stage asked for (the renderer may still show an earlier one)
  fs::path shader_root_;
  kit::Watchdog watchdog_;        // --timeout for each frame and each shader build
  kit::Scene scene_;
  kit::Window window_;
  std::unique_ptr<ImGuiSession> imgui_;
  std::unique_ptr<kit::Renderer> renderer_;
  std::unique_ptr<GpuTimer> gpu_timer_;
  std::unique_ptr<kit::Framebuffer> blit_source_;
  kit::CameraRig rig_;
  kit::View view_;
  std::map<fs::path, fs::file_time_type> watched_;
  std::string error_, note_;
  std::vector<std::string> warnings_;  // NaN/Inf and uniform warnings of the last check
  bool warnings_due_ = false;          // check at the next frame (shaders were built)
  bool in_frame_ = false;              // the watchdog times the current frame
  std::optional<FrameInputs> last_frame_inputs_;  // of the frame the renderer holds
  long shader_builds_ = 0;             // renderer builds and reloads: each may change the image
  int input_frames_left_ = 0;          // frames still to draw after the last input
  double frame_ms_ = 0.0;              // smoothed time of the frames that rendered
  std::vector<double> frame_times_[2]; // ms of each rendered frame: [0] while moving, [1] still
  glm::ivec2 frame_sizes_[2]{};        // the size each kind was last rendered at
  double cursor_x_ = 0.0, cursor_y_ = 0.0;
  float wheel_steps_ = 0.0f;
  glm::vec2 left_drag_{0.0f}, right_drag_{0.0f}, middle_drag_{0.0f};  // pixels since the last frame
  bool screenshot_requested_ = false;
};

}  // namespace

int main(int argc, char** argv) {
  ViewerOptions options;
  kit::name_gl_crashes("kit-view");
  return kit::run_tool("kit-view", 1, [&]() -> int {
    for (int i = 1; i < argc; ++i)
      if (!std::strcmp(argv[i], "--help") || !std::strcmp(argv[i], "-h")) {
        usage();
        return 0;
      }
    kit::parse_options(argc, argv, options.common, [&](const std::string& flag, const kit::OptionValue& value) -> int {
      if (flag == "--hidden") return options.hidden = true, 1;
      if (flag == "--no-ui") return options.ui = false, 1;
      if (flag == "--spin") return options.spin = true, 1;
      if (flag == "--timings") return options.timings = true, 1;
      if (flag == "--frames") return options.frames = parse_frame_count(value()), 2;
      if (flag == "--screenshot") return options.screenshot = value(), 2;
      if (flag == "--window-screenshot") return options.window_screenshot = value(), 2;
      if (flag == "--view") return options.view = kit::parse_view(value()), 2;
      return 0;
    });
    Viewer viewer(std::move(options));
    return viewer.run();
  });
}
