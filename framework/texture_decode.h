#pragma once
// Texture images of every scene format (glTF, OBJ/MTL): PNG or JPEG bytes decoded
// by OpenImageIO into RGBA8, the one form SceneGpu uploads.
#include <cstddef>
#include <string>

#include "scene.h"

namespace kit {

constexpr int kMaxTextureSide = 16384;  // pixels per side of a decoded texture

// Decodes `bytes`; the format is told by the magic bytes, not by a file name.
// Grey becomes RGB, a missing alpha 1. Throws kit::Error whose message starts with
// `what` (the image as the scene names it, e.g. "image 3 ('wood.png')") and says
// what is wrong: not PNG or JPEG, undecodable, too large, too many channels.
ImageRgba8 decode_texture_image(const unsigned char* bytes, size_t size, const std::string& what);

}  // namespace kit
