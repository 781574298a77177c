#include "environments.h"

#include <OpenImageIO/imageio.h>
#include <glm/glm.hpp>

#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "scene_math.h"

namespace kit_scenes {

namespace fs = std::filesystem;

namespace {

// Environments for lab 6 (common/render/ibl.h): equirectangular, RGB half-float EXR, in
// OUT_DIR/environments/. The mapping is environment.glsl's: texel (x, y) of a
// W x H image looks along phi = ((x + 0.5) / W - 0.5) 2 pi, theta = (y + 0.5) / H pi
// from +Y, direction (sin theta sin phi, cos theta, -sin theta cos phi).

constexpr int kEnvironmentWidth = 512;
constexpr int kEnvironmentHeight = 256;
constexpr int kEnvironmentSubsamples = 4;  // per texel side: a small source's edge is antialiased

using Radiance = glm::dvec3;

glm::dvec3 environment_direction(double u, double v) {
  const double phi = (u - 0.5) * 2.0 * kPi, theta = v * kPi;
  return {std::sin(theta) * std::sin(phi), std::cos(theta), -std::sin(theta) * std::cos(phi)};
}

glm::dvec3 direction_from_angles(double elevation_degrees, double azimuth_degrees) {
  // azimuth 0 looks along -Z (the image's centre), 90 along +X
  const double e = elevation_degrees * kPi / 180.0, a = azimuth_degrees * kPi / 180.0;
  return {std::cos(e) * std::sin(a), std::sin(e), -std::cos(e) * std::cos(a)};
}

// 1 inside a cone of `radius_degrees` around `axis`, 0 outside, with a soft edge of
// `edge_degrees` (0: hard, the subsamples antialias it).
double cone(const glm::dvec3& d, const glm::dvec3& axis, double radius_degrees, double edge_degrees) {
  const double angle = std::acos(std::clamp(glm::dot(d, axis), -1.0, 1.0)) * 180.0 / kPi;
  if (edge_degrees <= 0.0) return angle <= radius_degrees ? 1.0 : 0.0;
  return std::clamp((radius_degrees + edge_degrees - angle) / edge_degrees, 0.0, 1.0);
}

template <typename RadianceAt>
void write_environment(const fs::path& path, RadianceAt radiance_at) {
  std::vector<float> pixels(static_cast<size_t>(kEnvironmentWidth) * kEnvironmentHeight * 3);
  for (int y = 0; y < kEnvironmentHeight; ++y) {
    for (int x = 0; x < kEnvironmentWidth; ++x) {
      Radiance sum(0.0);
      for (int sy = 0; sy < kEnvironmentSubsamples; ++sy)
        for (int sx = 0; sx < kEnvironmentSubsamples; ++sx)
          sum += radiance_at(environment_direction((x + (sx + 0.5) / kEnvironmentSubsamples) / kEnvironmentWidth,
                                                   (y + (sy + 0.5) / kEnvironmentSubsamples) / kEnvironmentHeight));
      sum /= double(kEnvironmentSubsamples * kEnvironmentSubsamples);
      for (int c = 0; c < 3; ++c) pixels[(static_cast<size_t>(y) * kEnvironmentWidth + x) * 3 + c] = float(sum[c]);
    }
  }
  fs::create_directories(path.parent_path());
  auto out = OIIO::ImageOutput::create(path.string());
  if (!out) throw std::runtime_error("no EXR writer for " + path.string() + ": " + OIIO::geterror());
  OIIO::ImageSpec spec(kEnvironmentWidth, kEnvironmentHeight, 3, OIIO::TypeDesc::HALF);
  spec.attribute("compression", "zip");
  if (!out->open(path.string(), spec) || !out->write_image(OIIO::TypeDesc::FLOAT, pixels.data()) || !out->close())
    throw std::runtime_error("cannot write " + path.string() + ": " + out->geterror());
}

}  // namespace

// A sky with a small sun: the hard case for sampling. The sun's disc (1.5 degrees in
// radius) has radiance 1400, about 3000 times the sky's, so it gives an illuminance of
// about 3 on a surface facing it, comparable with the sky's own (about 1.6 overhead).
void write_sun_environment(const fs::path& path) {
  const glm::dvec3 sun = direction_from_angles(35.0, 60.0);
  write_environment(path, [&](const glm::dvec3& d) {
    if (d.y < 0.0) {  // ground: dark, warm, a little lighter towards the horizon
      const double t = std::pow(1.0 + d.y, 4.0);
      return Radiance(0.10, 0.085, 0.07) * (0.6 + 0.4 * t);
    }
    const double t = std::pow(1.0 - d.y, 3.0);  // 0 overhead, 1 at the horizon
    Radiance sky = glm::mix(Radiance(0.12, 0.25, 0.60), Radiance(0.55, 0.65, 0.80), t);
    return sky + Radiance(1400.0, 1330.0, 1200.0) * cone(d, sun, 1.5, 0.0);
  });
}

// A soft studio: a dim grey room lit by three large panels with soft edges (a key
// above front left, a fill to the right, a strip overhead behind).
void write_studio_environment(const fs::path& path) {
  const glm::dvec3 key = direction_from_angles(30.0, -40.0), fill = direction_from_angles(10.0, 80.0),
                   top = direction_from_angles(70.0, 180.0);
  write_environment(path, [&](const glm::dvec3& d) {
    const double up = 0.5 + 0.5 * d.y;
    Radiance room = glm::mix(Radiance(0.08, 0.075, 0.07), Radiance(0.30, 0.30, 0.32), up);
    room += Radiance(4.0, 3.8, 3.5) * cone(d, key, 18.0, 6.0);
    room += Radiance(1.2, 1.3, 1.5) * cone(d, fill, 22.0, 8.0);
    room += Radiance(2.0, 2.0, 2.0) * cone(d, top, 12.0, 5.0);
    return room;
  });
}

}  // namespace kit_scenes
