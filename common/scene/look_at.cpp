#include "scene/look_at.h"

#include <glm/gtc/matrix_transform.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "base/error.h"

namespace kit {

namespace {
constexpr double kMinFovDegrees = 1.0, kMaxFovDegrees = 179.0;
// Beyond this |cos| between the view direction and +Y, +Y cannot serve as "up".
constexpr double kVerticalCosine = 0.999;
}  // namespace

LookAt parse_look_at(const std::string& text, const std::string& flag) {
  const std::string usage = flag + " expects EYE_X,EYE_Y,EYE_Z,TARGET_X,TARGET_Y,TARGET_Z[,FOV_DEG] (got '" + text + "')";
  std::vector<double> numbers;
  size_t start = 0;
  while (true) {
    const size_t comma = text.find(',', start);
    const std::string part = text.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    try {
      size_t used = 0;
      const double value = std::stod(part, &used);
      if (used != part.size() || !std::isfinite(value)) throw std::invalid_argument(part);
      numbers.push_back(value);
    } catch (const std::exception&) {
      throw Error(usage + ": '" + part + "' is not a finite number");
    }
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  if (numbers.size() != 6 && numbers.size() != 7) throw Error(usage + ": " + std::to_string(numbers.size()) + " numbers");
  LookAt out;
  out.eye = glm::dvec3(numbers[0], numbers[1], numbers[2]);
  out.target = glm::dvec3(numbers[3], numbers[4], numbers[5]);
  if (out.eye == out.target) throw Error(usage + ": the eye and the target are the same point");
  if (numbers.size() == 7) {
    if (!(numbers[6] >= kMinFovDegrees && numbers[6] <= kMaxFovDegrees))
      throw Error(usage + ": the field of view must lie between 1 and 179 degrees");
    out.fov_degrees = numbers[6];
  }
  return out;
}

Camera look_at_camera(const LookAt& look_at, const Scene& scene) {
  const Camera framing = framing_camera(scene);
  Camera cam;
  const glm::dvec3 forward = glm::normalize(look_at.target - look_at.eye);
  const glm::dvec3 up = std::abs(forward.y) < kVerticalCosine ? glm::dvec3(0, 1, 0)
                                                               : glm::dvec3(0, 0, forward.y < 0.0 ? -1.0 : 1.0);
  cam.view = glm::mat4(glm::lookAt(look_at.eye, look_at.target, up));
  cam.position = glm::vec3(look_at.eye);
  cam.yfov = look_at.fov_degrees ? static_cast<float>(glm::radians(*look_at.fov_degrees)) : framing.yfov;
  // As framing_camera: the bounding sphere, with margin, between the planes.
  const glm::dvec3 center = 0.5 * (glm::dvec3(scene.bounds_min) + glm::dvec3(scene.bounds_max));
  const double radius = std::max(0.5 * glm::length(glm::dvec3(scene.bounds_max) - glm::dvec3(scene.bounds_min)), 1e-3);
  const double distance = glm::length(center - look_at.eye);
  const double zfar = distance + 1.5 * radius;
  cam.zfar = static_cast<float>(zfar);
  cam.znear = static_cast<float>(std::max(distance - 1.5 * radius, 1e-4 * zfar));
  return cam;
}

std::string look_at_text(const glm::vec3& eye, const glm::vec3& target, float yfov_radians) {
  char text[256];
  std::snprintf(text, sizeof text, "%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g", eye.x, eye.y, eye.z, target.x, target.y,
                target.z, glm::degrees(static_cast<double>(yfov_radians)));
  return text;
}

}  // namespace kit
