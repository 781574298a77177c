#pragma once
// Cameras placed from the command line: --look-at EYE_X,EYE_Y,EYE_Z,TARGET_X,TARGET_Y,TARGET_Z[,FOV_DEG]
// (cli.h), and the same text for the camera kit-view shows, so a view found by
// orbiting can be rendered headless again.
#include <glm/glm.hpp>

#include <optional>
#include <string>

#include "scene/scene.h"

namespace kit {

struct LookAt {
  glm::dvec3 eye{0.0}, target{0.0, 0.0, -1.0};
  std::optional<double> fov_degrees;  // vertical field of view; absent: the framing camera's
};

// Parses the flag's value (`flag` names it in messages). Throws kit::Error unless
// it is 6 or 7 comma-separated finite numbers, eye and target differ and the field
// of view lies in [1, 179] degrees.
LookAt parse_look_at(const std::string& text, const std::string& flag = "--look-at");

// A camera at `eye` looking at `target` with +Y up (+Z up, -Z looking down, when the
// view is within 2.6 degrees of vertical, where +Y up is undefined). Near and far
// planes enclose the scene's bounds as framing_camera's do.
Camera look_at_camera(const LookAt& look_at, const Scene& scene);

// "EX,EY,EZ,TX,TY,TZ,FOV" (6 significant digits, FOV in degrees): what --look-at reads.
std::string look_at_text(const glm::vec3& eye, const glm::vec3& target, float yfov_radians);

}  // namespace kit
