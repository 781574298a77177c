#pragma once
// Float images in memory, their PNG/EXR files (image_codecs.h; other formats are read
// through OpenImageIO, openimageio_formats.h), and
// read-back of GL textures. Rows are stored top-down, as image files are.
#include <optional>
#include <string>
#include <vector>

#include "gl/gl_objects.h"

namespace kit {

struct Image {
  int width = 0, height = 0, channels = 0;
  std::vector<float> pixels;  // row-major, top row first, `channels` floats per pixel

  Image() = default;
  Image(int w, int h, int c) : width(w), height(h), channels(c), pixels(static_cast<size_t>(w) * h * c, 0.0f) {}
  float& at(int x, int y, int c) { return pixels[(static_cast<size_t>(y) * width + x) * channels + c]; }
  float at(int x, int y, int c) const { return pixels[(static_cast<size_t>(y) * width + x) * channels + c]; }
};

// 8 bits a channel, as textures are decoded and uploaded.
struct ImageRgba8 {
  int width = 0, height = 0;
  std::vector<unsigned char> pixels;  // RGBA8, top row first
};

// How hard a PNG's zlib stream is squeezed: Smallest is zlib's default level (6),
// for files that are kept (handout images, kit-render's output); Fastest is level 1,
// for the grader's report images, 138 a submission: on those, zlib takes a quarter of
// the time (0.11 s against 0.43 s) for files 20 % larger (2.3 MB against 1.9 MB).
// Fastest also filters every row with libpng's Sub alone rather than letting it try
// all five per row: 0.86 ms an image against 1.40 ms, files 4 % larger (138 of a
// submission's report images re-encoded both ways, 2.27 MB against 2.18 MB).
enum class PngEffort { Smallest, Fastest };

// The 8-bit value a PNG stores for `v`: clamped to [0,1] (NaN and infinities as 0),
// times 255, rounded to nearest with halves away from zero, exactly as std::lround
// (checked on every float in [0,1]) but without its library call: lroundf was 3 % of
// the grader's CPU profile. floor(v * 255 + 0.5) is not the same: it rounds
// v = 0.0019607842 (0.49999997 after scaling) up.
unsigned char to_unorm8(float v);

// .exr keeps 32-bit floats; .png stores 8 bits per channel, values clamped to
// [0,1] and rounded to nearest (to_unorm8). Throws kit::Error.
void write_image(const std::string& path, const Image& image, PngEffort effort = PngEffort::Smallest);
Image read_image(const std::string& path);

// Reads a colour texture (any format) as RGBA floats, or a depth texture as one channel.
Image read_texture(const Texture2D& texture, bool depth = false);
// Mip level `level` of a colour texture (or the depth texture's level 0 with `depth`).
Image read_texture_level(const Texture2D& texture, int level, bool depth = false);

// Counts pixels with a NaN or Inf in any channel.
size_t count_non_finite(const Image& image);
// The first pixel (rows top-down) with a NaN or Inf in a channel, and that value; none when all are finite.
struct NonFinitePixel {
  int x = 0, y = 0;
  float value = 0.0f;
};
std::optional<NonFinitePixel> first_non_finite(const Image& image);

}  // namespace kit
