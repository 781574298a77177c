#pragma once
// The interactive camera of kit-view and the browser's page (kit-web): orbit and fly over
// one state, a target point, a distance and a direction (yaw, pitch). Until the first move
// the scene's own camera is used unchanged, so the first frame is the image kit-render makes.
#include <string>

#include <glm/glm.hpp>

#include "scene/scene.h"

namespace kit {

// Camera feel, relative to the scene's size so every scene handles alike.
constexpr float kRotateRadiansPerPixel = 0.006f;
constexpr float kLookRadiansPerPixel = 0.003f;
constexpr float kPanSpeed = 0.0015f;         // fraction of the orbit distance per pixel
constexpr float kZoomPerWheelStep = 0.9f;
constexpr float kMinDistanceFraction = 1e-3f;
constexpr float kFlySpeed = 0.25f;           // scene sizes per second
constexpr float kMaxPitch = 1.55f;           // just under 90 degrees: look-at stays well defined

class CameraRig {
 public:
  CameraRig(const Scene& scene, const Camera& initial);

  const Camera& camera() const { return camera_; }
  // The current view as --look-at's value, to render it headless.
  std::string look_at_text() const;
  bool flying() const { return flying_; }
  void toggle_fly() { flying_ = !flying_; }

  void rotate(float dx, float dy);  // orbit: turns the eye about the target (pixels dragged)
  void look(float dx, float dy);    // fly: turns the view about the eye
  void pan(float dx, float dy);
  void zoom(float steps);           // wheel steps; positive comes closer
  // move: x right, y up, z forward, in units of the fly speed; seconds of motion.
  void fly(const glm::vec3& move, float seconds);

 private:
  glm::vec3 forward() const;
  glm::vec3 eye() const { return target_ - forward() * distance_; }
  void turn(float yaw, float pitch);
  void update();

  Camera camera_;
  glm::vec3 target_{0.0f};
  float distance_ = 1.0f, yaw_ = 0.0f, pitch_ = 0.0f, scene_size_ = 1.0f;
  bool flying_ = false;
};

}  // namespace kit
