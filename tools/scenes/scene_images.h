// The textures kit-scenes writes (8-bit, generated, deterministic) and its PNG writer.
#pragma once

#include <glm/glm.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <vector>

namespace kit_scenes {

struct Image8 {
  int width = 0;
  int height = 0;
  int channels = 0;
  std::vector<std::uint8_t> pixels;  // row 0 is the top of the image

  Image8(int w, int h, int c) : width(w), height(h), channels(c), pixels(size_t(w) * h * c, 0) {}

  void set(int x, int y, glm::vec3 rgb01) {
    std::uint8_t* p = &pixels[(size_t(y) * width + x) * channels];
    for (int i = 0; i < 3; ++i)
      p[i] = std::uint8_t(std::lround(std::clamp(rgb01[i], 0.0f, 1.0f) * 255.0f));
  }
};

Image8 make_brick_color();
Image8 make_brick_normal();
Image8 make_checker();
Image8 make_alpha_ramp_checker();
Image8 make_bump_normal();
Image8 make_uv_grid();
Image8 make_packed_orm();
void write_png(const std::filesystem::path& path, const Image8& img);

}  // namespace kit_scenes
