#include "camera_rig.h"

#include <algorithm>
#include <cmath>

#include <glm/gtc/matrix_transform.hpp>

#include "scene/look_at.h"

namespace kit {

namespace {
constexpr glm::vec3 kUp{0.0f, 1.0f, 0.0f};
}  // namespace

CameraRig::CameraRig(const Scene& scene, const Camera& initial) : camera_(initial) {
  glm::mat4 inverse_view = glm::inverse(camera_.view);
  glm::vec3 eye(inverse_view[3]);
  glm::vec3 forward = -glm::normalize(glm::vec3(inverse_view[2]));
  glm::vec3 center = 0.5f * (scene.bounds_min + scene.bounds_max);
  scene_size_ = std::max(glm::length(scene.bounds_max - scene.bounds_min), 1e-3f);
  // Orbit about the point in front of the camera nearest the scene's centre.
  distance_ = std::max(glm::dot(center - eye, forward), 0.1f * scene_size_);
  target_ = eye + forward * distance_;
  pitch_ = std::asin(std::clamp(forward.y, -1.0f, 1.0f));
  yaw_ = std::atan2(forward.x, -forward.z);
}

std::string CameraRig::look_at_text() const { return kit::look_at_text(eye(), target_, camera_.yfov); }

void CameraRig::rotate(float dx, float dy) {
  turn(dx * kRotateRadiansPerPixel, dy * kRotateRadiansPerPixel);
  update();
}

void CameraRig::look(float dx, float dy) {
  glm::vec3 eye = this->eye();
  turn(dx * kLookRadiansPerPixel, dy * kLookRadiansPerPixel);
  target_ = eye + forward() * distance_;
  update();
}

void CameraRig::pan(float dx, float dy) {
  glm::vec3 right = glm::normalize(glm::cross(forward(), kUp));
  glm::vec3 up = glm::cross(right, forward());
  target_ += (-dx * right + dy * up) * distance_ * kPanSpeed;
  update();
}

void CameraRig::zoom(float steps) {
  distance_ = std::max(distance_ * std::pow(kZoomPerWheelStep, steps), kMinDistanceFraction * scene_size_);
  update();
}

void CameraRig::fly(const glm::vec3& move, float seconds) {
  glm::vec3 right = glm::normalize(glm::cross(forward(), kUp));
  target_ += (move.x * right + move.y * kUp + move.z * forward()) * kFlySpeed * scene_size_ * seconds;
  update();
}

glm::vec3 CameraRig::forward() const {
  return {std::cos(pitch_) * std::sin(yaw_), std::sin(pitch_), -std::cos(pitch_) * std::cos(yaw_)};
}

void CameraRig::turn(float yaw, float pitch) {
  yaw_ += yaw;
  pitch_ = std::clamp(pitch_ - pitch, -kMaxPitch, kMaxPitch);
}

void CameraRig::update() {
  camera_.view = glm::lookAt(eye(), target_, kUp);
  camera_.position = eye();
  // Zooming far out must not clip the scene away.
  camera_.zfar = std::max(camera_.zfar, distance_ + 2.0f * scene_size_);
}

}  // namespace kit
