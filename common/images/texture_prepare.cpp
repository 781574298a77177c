#include "images/texture_prepare.h"

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <cstring>  // stb_dxt.h calls memcpy without including it

// The packaged header (Debian's libstb-dev), compiled here: libstb.so does not build
// every function the header declares, and STB_DXT_STATIC keeps its names out of the
// link so they cannot meet another copy of stb.
#define STB_DXT_STATIC
#define STB_DXT_IMPLEMENTATION
#include <stb/stb_dxt.h>

#include "base/error.h"

namespace kit {

double srgb_to_linear(double c) { return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4); }

namespace {

constexpr int kBlockSide = 4;  // S3TC blocks are 4x4 texels
constexpr int kChannels = 4;   // RGBA

// 8-bit sRGB codes in linear light, and the linear values where rounding moves from
// one code to the next: a texel is encoded by a table and a step or two along the
// boundaries instead of a pow (or a binary search, whose branches cost as much).
struct SrgbTables {
  static constexpr int kStartBins = 4096;  // bins of [0, 1] each knowing the code at its low end
  std::array<double, 256> to_linear;
  std::array<double, 255> code_boundary;  // code_boundary[k]: linear value of code k + 0.5
  std::array<unsigned char, kStartBins + 1> start_code;
  SrgbTables() {
    for (int k = 0; k < 256; ++k) to_linear[static_cast<size_t>(k)] = srgb_to_linear(k / 255.0);
    for (int k = 0; k < 255; ++k) code_boundary[static_cast<size_t>(k)] = srgb_to_linear((k + 0.5) / 255.0);
    for (int bin = 0; bin <= kStartBins; ++bin) {
      const double low = static_cast<double>(bin) / kStartBins;
      start_code[static_cast<size_t>(bin)] = static_cast<unsigned char>(
          std::upper_bound(code_boundary.begin(), code_boundary.end(), low) - code_boundary.begin());
    }
  }
  // The code whose value is nearest `linear` in [0, 1] after encoding (a value on a
  // boundary rounds up): the number of boundaries at or below it.
  unsigned char encode(double linear) const {
    const double clamped = std::clamp(linear, 0.0, 1.0);
    unsigned code = start_code[static_cast<size_t>(clamped * kStartBins)];
    while (code < 255 && clamped >= code_boundary[code]) ++code;
    return static_cast<unsigned char>(code);
  }
};
const SrgbTables& srgb_tables() {
  static const SrgbTables tables;
  return tables;
}

// The source texels one destination texel covers along one side, with the part of
// each it covers divided by the destination texel's width (the weights sum to 1).
struct Footprint {
  int first = 0, count = 0;
  std::array<double, 3> weight{};  // a side of 2n + 1 texels halved to n: at most 3 texels each
};
std::vector<Footprint> footprints(int source, int destination) {
  std::vector<Footprint> result(static_cast<size_t>(destination));
  const double ratio = static_cast<double>(source) / destination;
  for (int d = 0; d < destination; ++d) {
    const double begin = d * ratio, end = (d + 1) * ratio;
    Footprint& f = result[static_cast<size_t>(d)];
    f.first = static_cast<int>(std::floor(begin));
    for (int s = f.first; s < source && s < end; ++s) {
      const double covered = std::min<double>(s + 1, end) - std::max<double>(s, begin);
      assert(f.count < static_cast<int>(f.weight.size()));
      f.weight[static_cast<size_t>(f.count++)] = covered / ratio;
    }
  }
  return result;
}

// The box filter from a source_width x source_height level to the next level's size:
// for each destination texel and channel, the sum of texel(x, y, c) over the source
// texels its area covers, weighted by the parts covered (footprints), handed to
// store(x, y, c, sum).
template <typename Texel, typename Store>
void box_filter(int source_width, int source_height, int width, int height, int channels, Texel texel, Store store) {
  const std::vector<Footprint> columns = footprints(source_width, width), rows = footprints(source_height, height);
  std::vector<double> sum(static_cast<size_t>(channels));
  for (int y = 0; y < height; ++y) {
    const Footprint& row = rows[static_cast<size_t>(y)];
    for (int x = 0; x < width; ++x) {
      const Footprint& column = columns[static_cast<size_t>(x)];
      std::fill(sum.begin(), sum.end(), 0.0);
      for (int j = 0; j < row.count; ++j)
        for (int i = 0; i < column.count; ++i) {
          const double weight = row.weight[static_cast<size_t>(j)] * column.weight[static_cast<size_t>(i)];
          for (int c = 0; c < channels; ++c) sum[static_cast<size_t>(c)] += weight * texel(column.first + i, row.first + j, c);
        }
      for (int c = 0; c < channels; ++c) store(x, y, c, sum[static_cast<size_t>(c)]);
    }
  }
}

// next_mip_level for even sides, where every texel is the mean of a 2x2 square: the
// same means without the general footprints' loops, on the path every power-of-two texture takes.
void halve_even_sides(const ImageRgba8& level, bool srgb, ImageRgba8& out) {
  const SrgbTables& tables = srgb_tables();
  const size_t source_row = static_cast<size_t>(level.width) * kChannels;
  for (int y = 0; y < out.height; ++y) {
    const unsigned char* top = &level.pixels[static_cast<size_t>(2 * y) * source_row];
    const unsigned char* bottom = top + source_row;
    unsigned char* dest = &out.pixels[static_cast<size_t>(y) * static_cast<size_t>(out.width) * kChannels];
    for (int x = 0; x < out.width; ++x, top += 2 * kChannels, bottom += 2 * kChannels, dest += kChannels)
      for (int c = 0; c < kChannels; ++c) {
        if (srgb && c < 3) {
          const double sum = tables.to_linear[top[c]] + tables.to_linear[top[c + kChannels]] +
                             tables.to_linear[bottom[c]] + tables.to_linear[bottom[c + kChannels]];
          dest[c] = tables.encode(0.25 * sum);
        } else {
          // The mean rounded half up, as the general path's floor(mean + 0.5).
          dest[c] = static_cast<unsigned char>((top[c] + top[c + kChannels] + bottom[c] + bottom[c + kChannels] + 2) / 4);
        }
      }
  }
}

}  // namespace

ImageRgba8 next_mip_level(const ImageRgba8& level, bool srgb) {
  ImageRgba8 out;
  out.width = std::max(1, level.width / 2);
  out.height = std::max(1, level.height / 2);
  out.pixels.resize(static_cast<size_t>(out.width) * static_cast<size_t>(out.height) * kChannels);
  if (level.width % 2 == 0 && level.height % 2 == 0) {
    halve_even_sides(level, srgb, out);
    return out;
  }
  const SrgbTables& tables = srgb_tables();
  auto texel = [&](int x, int y, int c) {
    const unsigned char code = level.pixels[(static_cast<size_t>(y) * static_cast<size_t>(level.width) + static_cast<size_t>(x)) * kChannels +
                                           static_cast<size_t>(c)];
    return srgb && c < 3 ? tables.to_linear[code] : static_cast<double>(code);
  };
  auto store = [&](int x, int y, int c, double value) {
    out.pixels[(static_cast<size_t>(y) * static_cast<size_t>(out.width) + static_cast<size_t>(x)) * kChannels + static_cast<size_t>(c)] =
        srgb && c < 3 ? tables.encode(value) : static_cast<unsigned char>(std::clamp(std::floor(value + 0.5), 0.0, 255.0));
  };
  box_filter(level.width, level.height, out.width, out.height, kChannels, texel, store);
  return out;
}

Image next_mip_level(const Image& level) {
  Image out(std::max(1, level.width / 2), std::max(1, level.height / 2), level.channels);
  box_filter(level.width, level.height, out.width, out.height, level.channels,
             [&](int x, int y, int c) { return static_cast<double>(level.at(x, y, c)); },
             [&](int x, int y, int c, double value) { out.at(x, y, c) = static_cast<float>(value); });
  return out;
}

bool is_opaque(const ImageRgba8& image) {
  for (size_t i = 3; i < image.pixels.size(); i += kChannels)
    if (image.pixels[i] != 255) return false;
  return true;
}

std::vector<unsigned char> compress_blocks(const ImageRgba8& image, TexelEncoding encoding) {
  if (encoding == TexelEncoding::Rgba8) throw Error("compress_blocks: RGBA8 is not a block encoding");
  const bool with_alpha = encoding == TexelEncoding::Bc3;
  const size_t block_bytes = with_alpha ? 16 : 8;
  const int blocks_x = (image.width + kBlockSide - 1) / kBlockSide, blocks_y = (image.height + kBlockSide - 1) / kBlockSide;
  std::vector<unsigned char> out(static_cast<size_t>(blocks_x) * static_cast<size_t>(blocks_y) * block_bytes);
  unsigned char block[kBlockSide * kBlockSide * kChannels];
  for (int by = 0; by < blocks_y; ++by)
    for (int bx = 0; bx < blocks_x; ++bx) {
      for (int row = 0; row < kBlockSide; ++row) {
        const int y = std::min(by * kBlockSide + row, image.height - 1);
        for (int column = 0; column < kBlockSide; ++column) {
          const int x = std::min(bx * kBlockSide + column, image.width - 1);
          std::memcpy(&block[(row * kBlockSide + column) * kChannels],
                      &image.pixels[(static_cast<size_t>(y) * static_cast<size_t>(image.width) + static_cast<size_t>(x)) * kChannels],
                      kChannels);
        }
      }
      stb_compress_dxt_block(&out[(static_cast<size_t>(by) * static_cast<size_t>(blocks_x) + static_cast<size_t>(bx)) * block_bytes],
                             block, with_alpha ? 1 : 0, STB_DXT_NORMAL);
    }
  return out;
}

PreparedTexture prepare_texture(ImageRgba8 image, bool srgb, bool compress) {
  PreparedTexture prepared;
  if (compress) prepared.encoding = is_opaque(image) ? TexelEncoding::Bc1 : TexelEncoding::Bc3;
  for (;;) {
    const bool last = image.width == 1 && image.height == 1;
    ImageRgba8 next = last ? ImageRgba8{} : next_mip_level(image, srgb);
    MipLevel& level = prepared.levels.emplace_back();
    level.width = image.width;
    level.height = image.height;
    level.bytes = compress ? compress_blocks(image, prepared.encoding) : std::move(image.pixels);
    if (last) break;
    image = std::move(next);
  }
  return prepared;
}

size_t prepared_bytes(const PreparedTexture& texture) {
  size_t bytes = 0;
  for (const MipLevel& level : texture.levels) bytes += level.bytes.size();
  return bytes;
}

}  // namespace kit
