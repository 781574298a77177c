#include "images/image_io.h"

#include <algorithm>
#include <cmath>

#include "base/error.h"
#include "gl/gl_flavour.h"
#include "images/image_codecs.h"
#include "images/openimageio_formats.h"

namespace kit {

unsigned char to_unorm8(float v) {
  v = std::isfinite(v) ? std::min(std::max(v, 0.0f), 1.0f) : 0.0f;
  const float scaled = v * 255.0f;
  const int whole = static_cast<int>(scaled);  // floor: scaled >= 0
  // scaled - whole is exact (both below 2^24), so the comparison decides the half exactly.
  return static_cast<unsigned char>(whole + (scaled - static_cast<float>(whole) >= 0.5f ? 1 : 0));
}

void write_image(const std::string& path, const Image& image, PngEffort effort) {
  if (has_extension(path, ".exr")) return write_exr(path, image);
  if (has_extension(path, ".png")) return write_png(path, image, effort);
  throw Error(path + ": output must end in .png or .exr");
}

Image read_image(const std::string& path) {
  if (has_extension(path, ".png")) return read_png(path);
  if (has_extension(path, ".exr")) return read_exr(path);
  return openimageio_formats().read_image(path, kMaxImageSide, kMaxImageSide);
}

Image read_texture(const Texture2D& texture, bool depth) { return read_texture_level(texture, 0, depth); }

Image read_texture_level(const Texture2D& texture, int level, bool depth) {
  if (depth && !can_read_depth_pixels())
    throw Error("reading a depth texture back: " + std::string(gl_flavour_name()) +
                " cannot read depth pixels (glReadPixels of GL_DEPTH_COMPONENT)");
  Framebuffer read_fbo;
  if (depth) {
    read_fbo.attach_depth(texture);
    draw_no_colour_buffer();
    glReadBuffer(GL_NONE);
  } else {
    read_fbo.attach_color(0, texture, level);
    glReadBuffer(GL_COLOR_ATTACHMENT0);
  }
  const int width = std::max(texture.width() >> level, 1), height = std::max(texture.height() >> level, 1);
  int channels = depth ? 1 : 4;
  Image flipped(width, height, channels);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  if (depth) glReadPixels(0, 0, width, height, GL_DEPTH_COMPONENT, GL_FLOAT, flipped.pixels.data());
  else read_colour_pixels_as_float(width, height, flipped.pixels.data());
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  check_gl("read_texture");
  // GL rows start at the bottom; images start at the top.
  Image image(width, height, channels);
  size_t row = static_cast<size_t>(width) * channels;
  for (int y = 0; y < height; ++y)
    std::copy_n(flipped.pixels.begin() + static_cast<std::ptrdiff_t>(row * (height - 1 - y)), row,
                image.pixels.begin() + static_cast<std::ptrdiff_t>(row * y));
  return image;
}

size_t count_non_finite(const Image& image) {
  size_t count = 0;
  for (size_t p = 0; p < image.pixels.size(); p += image.channels) {
    for (int c = 0; c < image.channels; ++c) {
      if (!std::isfinite(image.pixels[p + c])) {
        ++count;
        break;
      }
    }
  }
  return count;
}

std::optional<NonFinitePixel> first_non_finite(const Image& image) {
  for (size_t i = 0; i < image.pixels.size(); ++i)
    if (!std::isfinite(image.pixels[i])) {
      const size_t pixel = i / static_cast<size_t>(image.channels), width = static_cast<size_t>(image.width);
      return NonFinitePixel{static_cast<int>(pixel % width), static_cast<int>(pixel / width), image.pixels[i]};
    }
  return std::nullopt;
}

}  // namespace kit
