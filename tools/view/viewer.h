#pragma once
// kit-view's window onto one stage (kit_view.cpp reads the command line). The Viewer's
// parts are defined in the files beside this one: the frame loop and frame times
// (viewer.cpp), input and the camera (viewer_input.cpp), rendering, display and
// screenshots (viewer_frame.cpp), shader builds, hot reload and messages
// (viewer_shaders.cpp), and the window title and control panel (viewer_panel.cpp).
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "camera_rig.h"
#include "cli.h"
#include "base/watchdog.h"
#include "gl/gl_objects.h"
#include "gl/window.h"
#include "images/image_io.h"
#include "render/renderer.h"
#include "scene/scene.h"

namespace kit_view {

constexpr int kMaxViewerLights = 256;
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

void delete_query(GLuint id);

// GPU time of a frame's render and display, read a frame later so reading never stalls.
class GpuTimer {
 public:
  GpuTimer();
  void begin();
  void end();
  double milliseconds() const { return milliseconds_; }

 private:
  kit::GlName<delete_query> queries_[2];
  long frame_ = 0;
  double milliseconds_ = 0.0;
};

class ImGuiSession;  // viewer.cpp

class Viewer {
 public:
  explicit Viewer(ViewerOptions options);
  ~Viewer();
  int run();

 private:
  // ---- GLFW callbacks, keys, mouse and the camera (viewer_input.cpp).
  static Viewer& from(GLFWwindow* window);
  static Viewer& input(GLFWwindow* window);
  static void on_key(GLFWwindow* window, int key, int, int action, int);
  static void on_cursor(GLFWwindow* window, double x, double y);
  static void on_scroll(GLFWwindow* window, double, double dy);
  static void on_mouse_button(GLFWwindow* window, int, int, int);
  static void on_char(GLFWwindow* window, unsigned int);
  static void on_window_size(GLFWwindow* window, int, int);
  bool ui_wants_mouse() const;
  bool ui_wants_keyboard() const;
  void key(int key, int action);
  bool applies(int first, const char* what);
  void cycle_gamma();
  void select_view(kit::View view);
  void cursor_moved(double x, double y);
  void move_camera(float seconds);

  // ---- Rendering and display (viewer_frame.cpp).
  // What a rendered frame depends on. When all of it is as it was for the last
  // rendered frame, the viewer shows that frame again instead of rendering it anew.
  // The view is not in it: G-buffer views are drawn from the last frame's G-buffer.
  struct FrameInputs {
    kit::FrameCamera camera;
    kit::RenderSettings settings;  // its size is the window's; the size rendered at is below
    int width = 0, height = 0;
    long shader_builds = 0;
  };
  static bool same_frame(const FrameInputs& a, const FrameInputs& b);
  bool animated() const;
  enum class Rendered { None, Moving, Full };
  Rendered draw_frame(int width, int height, bool full_quality);
  void show(const kit::Texture2D& texture, int width, int height);
  kit::Image window_image();
  void write_final_screenshots();
  void write_key_screenshot();
  template <class MakeImage>
  bool save_image(const std::string& path, MakeImage make_image);

  // ---- Shaders: building, hot reload, errors (viewer_shaders.cpp).
  class TimedWork;
  std::string frame_activity() const;
  void build_renderer();
  void switch_stage(const kit::Stage& stage);
  bool stage_is_built() const;
  void reload();
  void reload_now();
  std::vector<std::filesystem::path> shader_files() const;
  using FileTimes = std::map<std::filesystem::path, std::filesystem::file_time_type>;
  FileTimes file_times() const;
  void poll_shader_files();
  void refresh_warnings();
  void set_note(const std::string& message);
  void report_error(const std::string& message);

  // ---- Frame times (viewer.cpp).
  void note_frame_time(Rendered rendered, double ms);
  void print_timings(int frames) const;

  // ---- Window title and control panel (viewer_panel.cpp).
  std::string title_prefix() const;
  void refresh_title();
  void draw_ui();
  float draw_messages();
  void draw_panel(float messages_height);

  // Members in construction order: the window (and its GL context) outlives everything that uses GL.
  ViewerOptions options_;
  kit::RenderSettings settings_;  // what the controls set; copied into the renderer each frame
  kit::LabSelection lab_;         // the stage and lab folders the command line asked for
  const kit::Stage* stage_;       // the stage asked for (the renderer may still show an earlier one)
  std::filesystem::path shader_root_;
  kit::Watchdog watchdog_;        // --timeout for each frame and each shader build
  kit::Scene scene_;
  kit::Window window_;
  std::unique_ptr<ImGuiSession> imgui_;
  std::unique_ptr<kit::Renderer> renderer_;
  std::unique_ptr<GpuTimer> gpu_timer_;
  std::unique_ptr<kit::Framebuffer> blit_source_;
  kit::CameraRig rig_;
  kit::View view_;
  std::map<std::filesystem::path, std::filesystem::file_time_type> watched_;
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

}  // namespace kit_view
