// The Viewer's frames (viewer.h): rendering when what a frame depends on changed, showing
// the view in the window, the GPU timer, and the screenshots.
#include "view/viewer.h"

#include <algorithm>
#include <string>
#include <system_error>

#include "base/error.h"
#include "gl/gl_flavour.h"

namespace fs = std::filesystem;

namespace kit_view {

namespace {

// While the camera moves, frames are rendered at 1/kMovingResolutionDivisor of the
// window's width and height (a quarter of the pixels: the passes after the geometry
// pass cost per pixel), then scaled up; the first frame the camera holds still is
// rendered at full size, so a still image is always the full-quality one.
constexpr int kMovingResolutionDivisor = 2;

}  // namespace

void delete_query(GLuint id) { glDeleteQueries(1, &id); }

GpuTimer::GpuTimer() {
  for (auto& q : queries_) {
    GLuint id = 0;
    glGenQueries(1, &id);
    q = kit::GlName<delete_query>(id);
  }
}

void GpuTimer::begin() {
  const auto& q = queries_[static_cast<size_t>(frame_ % 2)];
  if (frame_ >= 2 && kit::time_elapsed_ready(q.get()))
    milliseconds_ = static_cast<double>(kit::time_elapsed_ns(q.get())) * 1e-6;
  kit::begin_time_elapsed(q.get());
}

void GpuTimer::end() {
  kit::end_time_elapsed();
  ++frame_;
}

bool Viewer::same_frame(const FrameInputs& a, const FrameInputs& b) {
  return kit::same_frame_camera(a.camera, b.camera) && kit::same_image_settings(a.settings, b.settings) &&
         a.width == b.width && a.height == b.height && a.shader_builds == b.shader_builds;
}

// The custom effect may animate with u_time: it is rendered every frame.
bool Viewer::animated() const { return renderer_ && settings_.custom_effect && renderer_->stage().postprocess; }

// Renders the stage if what it depends on changed: at the window's size, or at
// 1/kMovingResolutionDivisor of it while the camera moves (unless `full_quality`);
// then shows the current view.
Viewer::Rendered Viewer::draw_frame(int width, int height, bool full_quality) {
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
void Viewer::show(const kit::Texture2D& texture, int width, int height) {
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
kit::Image Viewer::window_image() {
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

void Viewer::write_final_screenshots() {
  if (!options_.screenshot.empty()) {
    if (renderer_) save_image(options_.screenshot, [&] { return renderer_->read_view(kit::View::Final, false); });
    else report_error("no screenshot written: the stage did not build");
  }
  if (!options_.window_screenshot.empty()) save_image(options_.window_screenshot, [&] { return window_image(); });
}

void Viewer::write_key_screenshot() {
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
bool Viewer::save_image(const std::string& path, MakeImage make_image) {
  try {
    kit::write_image(path, make_image());
    set_note("wrote " + path);
    return true;
  } catch (const kit::Error& e) {
    report_error(e.what());
    return false;
  }
}

}  // namespace kit_view
