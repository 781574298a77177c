// The Viewer's input (viewer.h): GLFW's callbacks, the keys, mouse drags and the wheel,
// and the orbit or fly camera they move.
#include "view/viewer.h"

#include <imgui.h>

#include "gl/gl.h"  // glad before GLFW: GLFW_INCLUDE_NONE keeps GLFW's own GL header out
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

#include <algorithm>
#include <cmath>
#include <iterator>
#include <string>

namespace kit_view {

namespace {

// Frames drawn after the last input before the viewer waits for events again: Dear
// ImGui needs a frame or two to show what a click or a key did.
constexpr int kFramesAfterInput = 3;
constexpr float kGammaCycle[] = {2.2f, 1.0f, 0.5f, 2.5f};  // the G key, as in the gamma slides
constexpr float kFlyFastFactor = 4.0f;       // with Shift held: the fly speed (camera_rig.h) times this

}  // namespace

// ---- GLFW callbacks: the viewer is reached through the window's user pointer.
Viewer& Viewer::from(GLFWwindow* window) { return *static_cast<Viewer*>(glfwGetWindowUserPointer(window)); }
// Every callback counts as input: the next frames are drawn (kFramesAfterInput).
Viewer& Viewer::input(GLFWwindow* window) {
  Viewer& v = from(window);
  v.input_frames_left_ = kFramesAfterInput;
  return v;
}
void Viewer::on_key(GLFWwindow* window, int key, int, int action, int) { input(window).key(key, action); }
void Viewer::on_cursor(GLFWwindow* window, double x, double y) { input(window).cursor_moved(x, y); }
void Viewer::on_scroll(GLFWwindow* window, double, double dy) {
  Viewer& v = input(window);
  if (!v.ui_wants_mouse()) v.wheel_steps_ += static_cast<float>(dy);
}
void Viewer::on_mouse_button(GLFWwindow* window, int, int, int) { input(window); }
void Viewer::on_char(GLFWwindow* window, unsigned int) { input(window); }
void Viewer::on_window_size(GLFWwindow* window, int, int) { input(window); }

bool Viewer::ui_wants_mouse() const { return imgui_ && ImGui::GetIO().WantCaptureMouse; }
bool Viewer::ui_wants_keyboard() const { return imgui_ && ImGui::GetIO().WantCaptureKeyboard; }

void Viewer::key(int key, int action) {
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
bool Viewer::applies(int first, const char* what) {
  if (stage_->number >= first) return true;
  set_note(std::string(what) + " changes nothing before stage " + std::to_string(first) + " (" +
           kit::stages()[static_cast<size_t>(first - 1)].name + ")");
  return false;
}

void Viewer::cycle_gamma() {
  // The next preset after the one nearest the current gamma (the slider may sit between them).
  size_t nearest = 0;
  for (size_t i = 1; i < std::size(kGammaCycle); ++i)
    if (std::abs(kGammaCycle[i] - settings_.gamma) < std::abs(kGammaCycle[nearest] - settings_.gamma)) nearest = i;
  settings_.gamma = kGammaCycle[(nearest + 1) % std::size(kGammaCycle)];
}

void Viewer::select_view(kit::View view) {
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
void Viewer::cursor_moved(double x, double y) {
  glm::vec2 delta(static_cast<float>(x - cursor_x_), static_cast<float>(y - cursor_y_));
  cursor_x_ = x;
  cursor_y_ = y;
  if (ui_wants_mouse()) return;
  GLFWwindow* w = window_.handle();
  if (glfwGetMouseButton(w, GLFW_MOUSE_BUTTON_LEFT) == GLFW_PRESS) left_drag_ += delta;
  if (glfwGetMouseButton(w, GLFW_MOUSE_BUTTON_RIGHT) == GLFW_PRESS) right_drag_ += delta;
  if (glfwGetMouseButton(w, GLFW_MOUSE_BUTTON_MIDDLE) == GLFW_PRESS) middle_drag_ += delta;
}

void Viewer::move_camera(float seconds) {
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

}  // namespace kit_view
