#pragma once
// Scene textures made ready for upload on SceneGpu's decode threads: the mip chain
// filtered on the CPU and, for large ones when allowed, the levels compressed to S3TC
// (BC) blocks, so that the GL thread only copies bytes. On llvmpipe glGenerateMipmap
// runs on the GL thread (about 90 ms and 10 MB a 2048x2048 texture) and JIT-compiles
// a blit per format in each process (0.1-0.2 s for a kit scene's three 256x256
// textures, paid by every grader child); a BC1 chain holds an eighth of RGBA8's bytes.
#include <cstddef>
#include <vector>

#include "images/image_io.h"
#include "images/texture_compression.h"

namespace kit {

// IEC 61966-2-1's sRGB transfer function (decode), for c in [0, 1].
double srgb_to_linear(double c);

// How a level's bytes hold its texels.
enum class TexelEncoding {
  Rgba8,  // 4 bytes a texel, top row first
  Bc1,    // S3TC DXT1: 8 bytes a 4x4 block, opaque RGB (4 colours: two end points and two between)
  Bc3,    // S3TC DXT5: 16 bytes a 4x4 block, BC1's colour plus an 8-step interpolated alpha
};

struct MipLevel {
  int width = 0, height = 0;
  std::vector<unsigned char> bytes;
};

// Levels 0 to 1x1, each half the one before (rounded down, at least 1), all in one encoding.
struct PreparedTexture {
  TexelEncoding encoding = TexelEncoding::Rgba8;
  std::vector<MipLevel> levels;
};

// The next mip level: size max(1, side / 2), each texel the mean of the source texels
// its area covers (2x2 for even sides; along an odd side a texel covered in part is
// weighted by that part: a box filter). With `srgb` the colour is averaged in linear light and encoded
// again, as GL filters sRGB textures; alpha and linear data are averaged as stored.
// Rounded to the nearest 8-bit value.
ImageRgba8 next_mip_level(const ImageRgba8& level, bool srgb);

// The next mip level of a float image of any channel count: next_mip_level's box
// filter, summed in double, nothing encoded (the environment maps' chains, ibl.cpp).
Image next_mip_level(const Image& level);

// Whether every texel's alpha is 255: BC1 then keeps it, else BC3 is needed.
bool is_opaque(const ImageRgba8& image);

// `image` as BC1 or BC3 blocks (stb_dxt), row by row of blocks; a side that is not a
// multiple of 4 is padded by repeating its last texel. `encoding` must not be Rgba8.
std::vector<unsigned char> compress_blocks(const ImageRgba8& image, TexelEncoding encoding);

// `image` with its mip chain (next_mip_level), every level compressed to BC1, or BC3
// when alpha is not all 255, when `compress` says so, RGBA8 otherwise. Each level's
// RGBA8 pixels are dropped once the next is made from them.
PreparedTexture prepare_texture(ImageRgba8 image, bool srgb, bool compress);
// The bytes of every level of `texture`.
size_t prepared_bytes(const PreparedTexture& texture);

}  // namespace kit
