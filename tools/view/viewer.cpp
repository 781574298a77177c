// The Viewer's construction, its frame loop and the frame times it keeps (viewer.h).
#include "view/viewer.h"

#include <imgui.h>
#include <imgui_impl_glfw.h>
#include <imgui_impl_opengl3.h>

#include "gl/gl.h"  // glad before GLFW: GLFW_INCLUDE_NONE keeps GLFW's own GL header out
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

#include <algorithm>
#include <cstdio>
#include <utility>

namespace kit_view {

namespace {

constexpr const char* kImGuiGlslVersion = "#version 330 core";
constexpr double kShaderPollSeconds = 0.25;    // how often shader files are checked for changes
constexpr double kTitleRefreshSeconds = 0.25;  // the title shows the frame time, but not every frame
constexpr double kWarningCheckSeconds = 2.0;   // NaN/Inf read-back and uniform check (a read-back costs a few ms)
constexpr double kFrameTimeSmoothing = 0.05;   // weight of the newest frame in the moving average
constexpr float kSpinPixelsPerFrame = 8.0f;    // --spin: a steady left drag of this many pixels a frame
constexpr double kMaxFlyStepSeconds = 0.1;     // the longest step one frame flies (the loop may have slept)

}  // namespace

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

Viewer::Viewer(ViewerOptions options)
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

Viewer::~Viewer() = default;

int Viewer::run() {
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

// ---- Frame times: of the frames that rendered, from the end of the event wait to after the swap.
void Viewer::note_frame_time(Rendered rendered, double ms) {
  frame_ms_ = frame_times_[0].empty() && frame_times_[1].empty() ? ms : frame_ms_ + kFrameTimeSmoothing * (ms - frame_ms_);
  const int kind = rendered == Rendered::Moving ? 0 : 1;
  frame_times_[kind].push_back(ms);
  if (last_frame_inputs_) frame_sizes_[kind] = {last_frame_inputs_->width, last_frame_inputs_->height};
}

// --timings: how many frames rendered, at which size, and their median times.
void Viewer::print_timings(int frames) const {
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

}  // namespace kit_view
