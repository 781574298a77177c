#pragma once
// Texture images of every scene format (glTF, OBJ/MTL): PNG bytes decoded by libpng,
// JPEG bytes by OpenImageIO (openimageio_formats.h), into RGBA8, the one form SceneGpu uploads.
#include <cstddef>
#include <string>

#include "base/error.h"
#include "images/image_io.h"

namespace kit {

// An image of a scene. Loading keeps only its encoded bytes, with the header
// checked: SceneGpu decodes the images materials use, once each and on worker
// threads, uploads each in the format its material slots need, and keeps no
// decoded copy (decode_scene_image below decodes one for tests and tools).
struct SceneImage {
  std::string what;                    // how messages name it: "scene.gltf: image 3 ('wood.png')"
  int width = 0, height = 0;
  std::vector<unsigned char> encoded;  // PNG or JPEG bytes; empty when `decoded` holds the pixels
  ImageRgba8 decoded;                  // pixels made in memory (tests, generated scenes)
};

constexpr int kMaxTextureSide = 16384;  // pixels per side of a decoded texture

struct TextureHeader {
  int width = 0, height = 0;
};

// Throws kit::Error starting with `what` when a texture's header says it is larger than
// kMaxTextureSide a side or has other than 1 to 4 channels; checked before any pixel is
// decoded. Inline: OpenImageIO's module (openimageio_formats.h) checks JPEGs with it too.
inline void check_texture_size(int width, int height, int channels, const std::string& what) {
  if (width <= 0 || height <= 0 || width > kMaxTextureSide || height > kMaxTextureSide || channels < 1 || channels > 4)
    throw Error(what + " is " + std::to_string(width) + "x" + std::to_string(height) + " with " +
                std::to_string(channels) + " channels (at most " + std::to_string(kMaxTextureSide) +
                " pixels a side and 4 channels)");
}
// Checks PNG or JPEG bytes as decode_texture_image does, reading only the header:
// scenes are checked at load, and decoded later, once, by SceneGpu.
TextureHeader read_texture_header(const unsigned char* bytes, size_t size, const std::string& what);

// Decodes `bytes`; the format is told by the magic bytes, not by a file name.
// Grey becomes RGB, a missing alpha 1. Throws kit::Error whose message starts with
// `what` (the image as the scene names it, e.g. "image 3 ('wood.png')") and says
// what is wrong: not PNG or JPEG, undecodable, too large, too many channels.
ImageRgba8 decode_texture_image(const unsigned char* bytes, size_t size, const std::string& what);

// A scene image's pixels: its `decoded` pixels, or its encoded bytes decoded.
ImageRgba8 decode_scene_image(const SceneImage& image);

}  // namespace kit
