#pragma once
// PNG and OpenEXR, the two formats the kit itself reads and writes, through libpng and
// OpenEXR directly. Every other format (JPEG textures, a Radiance .hdr environment, ...)
// goes through OpenImageIO (openimageio_formats.h), which is loaded only when a file
// needs it: OpenImageIO's ~260 shared libraries took 0.2 s of every program's start,
// a fifth of grading one submission, and a grading run needs PNG and EXR alone.
#include <cstddef>
#include <string>
#include <vector>

#include "images/image_io.h"

namespace kit {

// The largest image side read from a file whose caller sets no limit of its own: an
// environment's widest (ibl.h) is 16384 texels.
constexpr int kMaxImageSide = 16384;

// Whether `path` ends in `extension` (given in lower case), in any case: ".PNG" is ".png".
bool has_extension(const std::string& path, const std::string& extension);

// Whether `bytes` start with PNG's signature.
bool is_png(const unsigned char* bytes, size_t size);

// A PNG's size without decoding it. Throws kit::Error starting with `what`.
struct PngHeader {
  int width = 0, height = 0, channels = 0;  // channels after expansion: 1 grey, 2 grey+alpha, 3 RGB, 4 RGBA
};
PngHeader read_png_header(const unsigned char* bytes, size_t size, const std::string& what);

// A PNG as 8 bits a channel: palettes and low bit depths expanded (tRNS to alpha),
// 16 bits scaled to 8 with rounding, values as stored (no gamma conversion, alpha not
// premultiplied: glTF and MTL mean a PNG's colour as it is). Images over `max_side`
// pixels a side are refused before any pixel is decoded. Throws kit::Error starting
// with `what`.
struct Pixels8 {  // 8 bits a channel, as decoded (JPEG through OpenImageIO too)
  int width = 0, height = 0, channels = 0;
  std::vector<unsigned char> pixels;  // rows top-down, `channels` bytes a pixel
};
Pixels8 decode_png8(const unsigned char* bytes, size_t size, const std::string& what, int max_side);

// A PNG file as floats: 8-bit values v as v * (1/255), 16-bit ones as v * (1/65535),
// as OpenImageIO converts them (the kit's references were read that way).
Image read_png(const std::string& path);
// 8 bits a channel (1-4 channels), values clamped and rounded by to_unorm8.
void write_png(const std::string& path, const Image& image, PngEffort effort);

// An OpenEXR file's R, G, B and A channels (those it has, in that order; a lone
// channel of any name as grey) as 32-bit floats, whatever their stored type; larger
// than `max_width` x `max_height` is refused from the header. Throws kit::Error naming the file.
Image read_exr(const std::string& path, int max_width = kMaxImageSide, int max_height = kMaxImageSide);
// 32-bit float channels R, G, B, A (as many as the image has; 1 channel is Y), ZIP compression.
void write_exr(const std::string& path, const Image& image);

}  // namespace kit
