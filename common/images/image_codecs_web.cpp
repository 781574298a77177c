// The browser build's image codecs (KIT_WEB; common/CMakeLists.txt compiles this file
// there instead of image_codecs.cpp and openimageio_formats.cpp): libpng, OpenEXR and
// OpenImageIO have no WebAssembly build among Debian's packages, and emscripten's ports
// of them download their sources. PNG, JPEG and Radiance .hdr are decoded by stb_image
// (Debian's libstb-dev, header only); OpenEXR scan-line files (the kit's environments
// and its written images: uncompressed, ZIPS or ZIP, half, float or uint channels) by
// read_exr below, inflating with stb_image's zlib decoder. Writing images is refused.
#include "images/image_codecs.h"
#include "images/openimageio_formats.h"

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <memory>

#include "base/error.h"
#include "base/safe_file.h"
#include "base/text.h"

// The packaged header, compiled here with its functions private to this file (as
// texture_prepare.cpp compiles stb_dxt.h): only the decoders the kit needs.
#define STBI_ONLY_PNG
#define STBI_ONLY_JPEG
#define STBI_ONLY_HDR
#define STBI_NO_STDIO
#define STBI_NO_FAILURE_STRINGS_IF_UNUSED
#define STB_IMAGE_STATIC
#define STB_IMAGE_IMPLEMENTATION
#if defined(__clang__)
#pragma clang diagnostic push
#pragma clang diagnostic ignored "-Wunused-function"
#endif
#include <stb/stb_image.h>
#if defined(__clang__)
#pragma clang diagnostic pop
#endif

namespace kit {

namespace {

struct StbFree {
  void operator()(void* p) const { stbi_image_free(p); }
};

int as_int(size_t size) { return static_cast<int>(std::min<size_t>(size, 0x7fffffff)); }

std::string stb_reason() {
  const char* why = stbi_failure_reason();
  return why ? why : "unknown error";
}

// The size and channels stb_image reports, refused over `max_side` before any pixel is decoded.
void check_header(const unsigned char* bytes, size_t size, const std::string& what, int max_side, int* w, int* h,
                  int* n) {
  if (!stbi_info_from_memory(bytes, as_int(size), w, h, n)) throw Error(what + " could not be decoded: " + stb_reason());
  if (*w > max_side || *h > max_side)
    throw Error(what + " is " + std::to_string(*w) + "x" + std::to_string(*h) + ", over the " +
                std::to_string(max_side) + "-pixel limit a side");
}

// 8 bits a channel as stored: 16-bit PNG samples scaled with rounding, as libpng's
// png_set_scale_16 does on the desktop (stb_image's own 16-to-8 drops the low byte).
Pixels8 decode8(const unsigned char* bytes, size_t size, const std::string& what, int max_side) {
  int w = 0, h = 0, n = 0;
  check_header(bytes, size, what, max_side, &w, &h, &n);
  Pixels8 out;
  if (stbi_is_16_bit_from_memory(bytes, as_int(size))) {
    std::unique_ptr<stbi_us, StbFree> data(stbi_load_16_from_memory(bytes, as_int(size), &w, &h, &n, 0));
    if (!data) throw Error(what + " could not be decoded: " + stb_reason());
    out = {w, h, n, std::vector<unsigned char>(static_cast<size_t>(w) * h * n)};
    for (size_t i = 0; i < out.pixels.size(); ++i)
      out.pixels[i] = static_cast<unsigned char>((static_cast<unsigned>(data.get()[i]) * 255u + 32767u) / 65535u);
    return out;
  }
  std::unique_ptr<stbi_uc, StbFree> data(stbi_load_from_memory(bytes, as_int(size), &w, &h, &n, 0));
  if (!data) throw Error(what + " could not be decoded: " + stb_reason());
  out = {w, h, n, std::vector<unsigned char>(data.get(), data.get() + static_cast<size_t>(w) * h * n)};
  return out;
}

std::vector<unsigned char> read_whole(const std::string& path) {
  constexpr std::uintmax_t kMaxImageFileBytes = static_cast<std::uintmax_t>(kMaxImageSide) * kMaxImageSide * 8;
  SafeOpen how;
  how.follow_link = true;
  return read_regular_file(path, kMaxImageFileBytes, how);
}

Image read_any(const std::string& path, int max_width, int max_height) {
  const std::vector<unsigned char> bytes = read_whole(path);
  int w = 0, h = 0, n = 0;
  check_header(bytes.data(), bytes.size(), path, std::max(max_width, max_height), &w, &h, &n);
  if (w > max_width || h > max_height)
    throw Error(path + " is " + std::to_string(w) + "x" + std::to_string(h) + ", over the " + std::to_string(max_width) +
                "x" + std::to_string(max_height) + " limit");
  Image image;
  if (stbi_is_hdr_from_memory(bytes.data(), as_int(bytes.size()))) {
    std::unique_ptr<float, StbFree> data(stbi_loadf_from_memory(bytes.data(), as_int(bytes.size()), &w, &h, &n, 0));
    if (!data) throw Error(path + " could not be decoded: " + stb_reason());
    image = Image(w, h, n);
    std::copy_n(data.get(), image.pixels.size(), image.pixels.begin());
    return image;
  }
  if (has_extension(path, ".png")) return read_png(path);
  const Pixels8 p = decode8(bytes.data(), bytes.size(), path, std::max(max_width, max_height));
  image = Image(p.width, p.height, p.channels);
  for (size_t i = 0; i < image.pixels.size(); ++i) image.pixels[i] = static_cast<float>(p.pixels[i]) * (1.0f / 255.0f);
  return image;
}

TextureHeader jpeg_header(const unsigned char* bytes, size_t size, const std::string& what) {
  int w = 0, h = 0, n = 0;
  check_header(bytes, size, what, kMaxTextureSide, &w, &h, &n);
  return {w, h};
}

Pixels8 decode_jpeg(const unsigned char* bytes, size_t size, const std::string& what) {
  return decode8(bytes, size, what, kMaxTextureSide);
}

}  // namespace

bool has_extension(const std::string& path, const std::string& extension) {
  return path.size() >= extension.size() && lower_case(path.substr(path.size() - extension.size())) == extension;
}

bool is_png(const unsigned char* bytes, size_t size) {
  static const unsigned char kSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
  return size >= 8 && std::memcmp(bytes, kSignature, 8) == 0;
}

PngHeader read_png_header(const unsigned char* bytes, size_t size, const std::string& what) {
  if (!is_png(bytes, size)) throw Error(what + " is not a PNG");
  PngHeader header;
  if (!stbi_info_from_memory(bytes, as_int(size), &header.width, &header.height, &header.channels))
    throw Error(what + " could not be decoded: " + stb_reason());
  return header;
}

Pixels8 decode_png8(const unsigned char* bytes, size_t size, const std::string& what, int max_side) {
  if (!is_png(bytes, size)) throw Error(what + " is not a PNG");
  return decode8(bytes, size, what, max_side);
}

Image read_png(const std::string& path) {
  const std::vector<unsigned char> bytes = read_whole(path);
  if (!is_png(bytes.data(), bytes.size())) throw Error(path + " is not a PNG");
  int w = 0, h = 0, n = 0;
  check_header(bytes.data(), bytes.size(), path, kMaxImageSide, &w, &h, &n);
  // 16-bit samples as v / 65535, 8-bit ones as v / 255, as on the desktop.
  if (stbi_is_16_bit_from_memory(bytes.data(), as_int(bytes.size()))) {
    std::unique_ptr<stbi_us, StbFree> data(stbi_load_16_from_memory(bytes.data(), as_int(bytes.size()), &w, &h, &n, 0));
    if (!data) throw Error(path + " could not be decoded: " + stb_reason());
    Image image(w, h, n);
    for (size_t i = 0; i < image.pixels.size(); ++i) image.pixels[i] = static_cast<float>(data.get()[i]) * (1.0f / 65535.0f);
    return image;
  }
  const Pixels8 p = decode8(bytes.data(), bytes.size(), path, kMaxImageSide);
  Image image(p.width, p.height, p.channels);
  for (size_t i = 0; i < image.pixels.size(); ++i) image.pixels[i] = static_cast<float>(p.pixels[i]) * (1.0f / 255.0f);
  return image;
}

namespace {

// OpenEXR's half (IEEE 754 binary16) as a float, exactly: subnormals, infinities and NaNs
// included, as OpenEXR's own conversion gives them.
float half_to_float(uint16_t h) {
  const uint32_t sign = static_cast<uint32_t>(h & 0x8000u) << 16;
  uint32_t exponent = (h >> 10) & 0x1Fu, mantissa = h & 0x3FFu, bits;
  if (exponent == 0x1F) {
    bits = sign | 0x7F800000u | (mantissa << 13);
  } else if (exponent != 0) {
    bits = sign | ((exponent + 112) << 23) | (mantissa << 13);
  } else if (mantissa == 0) {
    bits = sign;
  } else {  // subnormal: normalised in float's wider exponent range
    exponent = 113;
    while (!(mantissa & 0x400u)) {
      mantissa <<= 1;
      --exponent;
    }
    bits = sign | (exponent << 23) | ((mantissa & 0x3FFu) << 13);
  }
  float f;
  std::memcpy(&f, &bits, sizeof f);
  return f;
}

// Little-endian reads from a file's bytes, each checked against its end.
struct ExrBytes {
  const std::vector<unsigned char>& bytes;
  const std::string& path;
  size_t at = 0;
  void need(size_t n) const {
    if (at > bytes.size() || bytes.size() - at < n) throw Error(path + ": the EXR ends early (cannot read it)");
  }
  uint32_t u32() {
    need(4);
    uint32_t v = 0;
    for (int i = 3; i >= 0; --i) v = (v << 8) | bytes[at + static_cast<size_t>(i)];
    at += 4;
    return v;
  }
  int32_t i32() { return static_cast<int32_t>(u32()); }
  uint64_t u64() {
    const uint64_t low = u32();
    return low | (static_cast<uint64_t>(u32()) << 32);
  }
  std::string name() {
    const size_t end = std::find(bytes.begin() + static_cast<std::ptrdiff_t>(std::min(at, bytes.size())), bytes.end(), 0) -
                       bytes.begin();
    if (end >= bytes.size()) throw Error(path + ": the EXR's header is cut short");
    std::string s(bytes.begin() + static_cast<std::ptrdiff_t>(at), bytes.begin() + static_cast<std::ptrdiff_t>(end));
    at = end + 1;
    return s;
  }
};

struct ExrChannel {
  std::string name;
  int type = 0;  // 0 uint, 1 half, 2 float
  int x_sampling = 1, y_sampling = 1;
  size_t bytes() const { return type == 1 ? 2 : 4; }
};

}  // namespace

Image read_exr(const std::string& path, int max_width, int max_height) {
  const std::vector<unsigned char> bytes = read_whole(path);
  ExrBytes in{bytes, path};
  if (in.u32() != 20000630u) throw Error(path + ": not an OpenEXR file");
  const uint32_t version = in.u32();
  if ((version & 0xFFu) != 2 || (version & 0x1A00u))  // tiled, deep or multi-part
    throw Error(path + ": a tiled, deep or multi-part EXR (the browser build reads scan-line images only)");
  std::vector<ExrChannel> channels;
  int compression = -1;
  int32_t box[4] = {0, 0, -1, -1};
  for (std::string attribute = in.name(); !attribute.empty(); attribute = in.name()) {
    const std::string type = in.name();
    const uint32_t size = in.u32();
    in.need(size);
    const size_t end = in.at + size;
    if (attribute == "channels" && type == "chlist") {
      for (std::string channel = in.name(); !channel.empty() && in.at < end; channel = in.name()) {
        ExrChannel c;
        c.name = channel;
        c.type = in.i32();
        in.u32();  // pLinear and reserved bytes
        c.x_sampling = in.i32();
        c.y_sampling = in.i32();
        if (c.type < 0 || c.type > 2) throw Error(path + ": channel " + channel + " has an unknown pixel type");
        channels.push_back(c);
      }
    } else if (attribute == "compression" && size >= 1) {
      compression = bytes[in.at];
    } else if (attribute == "dataWindow" && size >= 16) {
      for (int32_t& v : box) v = in.i32();
    }
    in.at = end;
  }
  // Lines a chunk holds: uncompressed and ZIPS one, ZIP sixteen.
  const int lines_per_chunk = compression == 0 || compression == 2 ? 1 : compression == 3 ? 16 : 0;
  if (lines_per_chunk == 0)
    throw Error(path + ": EXR compression " + std::to_string(compression) +
                " (the browser build reads uncompressed, ZIPS and ZIP EXRs; the kit writes ZIP)");
  const long width = static_cast<long>(box[2]) - box[0] + 1, height = static_cast<long>(box[3]) - box[1] + 1;
  if (width < 1 || height < 1 || width > max_width || height > max_height)
    throw Error(path + ": the image is " + std::to_string(width) + "x" + std::to_string(height) + " pixels (at most " +
                std::to_string(max_width) + "x" + std::to_string(max_height) + ")");
  // The channels read, as read_exr on the desktop takes them: R, G, B, A, else a lone one.
  std::vector<int> wanted;  // index in `channels` of each output channel
  for (const char* name : {"R", "G", "B", "A"})
    for (size_t i = 0; i < channels.size(); ++i)
      if (channels[i].name == name) wanted.push_back(static_cast<int>(i));
  if (wanted.empty() && channels.size() == 1) wanted.push_back(0);
  if (wanted.empty()) throw Error(path + ": an EXR without R, G, B, A or a single grey channel");
  for (const ExrChannel& c : channels)
    if (c.x_sampling != 1 || c.y_sampling != 1)
      throw Error(path + ": channel " + c.name + " is subsampled (the kit reads full-resolution channels only)");
  size_t line_bytes = 0;
  for (const ExrChannel& c : channels) line_bytes += c.bytes() * static_cast<size_t>(width);

  Image image(static_cast<int>(width), static_cast<int>(height), static_cast<int>(wanted.size()));
  const long chunks = (height + lines_per_chunk - 1) / lines_per_chunk;
  std::vector<uint64_t> offsets(static_cast<size_t>(chunks));
  for (uint64_t& offset : offsets) offset = in.u64();
  std::vector<unsigned char> inflated, data;
  for (uint64_t offset : offsets) {
    in.at = static_cast<size_t>(std::min<uint64_t>(offset, bytes.size()));
    const long first = static_cast<long>(in.i32()) - box[1];
    const uint32_t size = in.u32();
    in.need(size);
    if (first < 0 || first >= height) throw Error(path + ": a chunk of the EXR lies outside its image");
    const long lines = std::min<long>(lines_per_chunk, height - first);
    const size_t expected = line_bytes * static_cast<size_t>(lines);
    const char* packed = reinterpret_cast<const char*>(bytes.data() + in.at);
    if (size < expected) {  // ZIP(S): zlib, then OpenEXR's byte predictor and interleaving undone
      inflated.resize(expected);
      if (stbi_zlib_decode_buffer(reinterpret_cast<char*>(inflated.data()), static_cast<int>(expected), packed,
                                  static_cast<int>(size)) != static_cast<int>(expected))
        throw Error(path + ": a chunk of the EXR does not inflate to its size");
      for (size_t i = 1; i < expected; ++i) inflated[i] = static_cast<unsigned char>(inflated[i - 1] + inflated[i] - 128);
      data.resize(expected);
      const size_t half = (expected + 1) / 2;
      for (size_t i = 0; i < expected; ++i) data[i] = inflated[i % 2 == 0 ? i / 2 : half + i / 2];
    } else {
      data.assign(bytes.begin() + static_cast<std::ptrdiff_t>(in.at),
                  bytes.begin() + static_cast<std::ptrdiff_t>(in.at + expected));
    }
    // Each line holds every channel's values in the header's (alphabetical) order.
    size_t at = 0;
    for (long line = 0; line < lines; ++line) {
      float* row = image.pixels.data() + static_cast<size_t>(first + line) * static_cast<size_t>(width) * wanted.size();
      for (size_t c = 0; c < channels.size(); ++c) {
        const auto out = std::find(wanted.begin(), wanted.end(), static_cast<int>(c));
        const size_t slot = static_cast<size_t>(out - wanted.begin());
        for (long x = 0; x < width; ++x, at += channels[c].bytes()) {
          if (out == wanted.end()) continue;
          float value;
          if (channels[c].type == 1) {
            value = half_to_float(static_cast<uint16_t>(data[at] | (data[at + 1] << 8)));
          } else {
            uint32_t v = 0;
            for (int i = 3; i >= 0; --i) v = (v << 8) | data[at + static_cast<size_t>(i)];
            if (channels[c].type == 2) std::memcpy(&value, &v, sizeof value);
            else value = static_cast<float>(v);
          }
          row[static_cast<size_t>(x) * wanted.size() + slot] = value;
        }
      }
    }
  }
  return image;
}

void write_png(const std::string& path, const Image&, PngEffort) {
  throw Error(path + ": the browser build writes no image files (it shows them in its canvas)");
}

void write_exr(const std::string& path, const Image&) {
  throw Error(path + ": the browser build writes no image files (it shows them in its canvas)");
}

const OpenImageIoFormats& openimageio_formats() {
  // Not OpenImageIO: stb_image's decoders behind the same table, for JPEG textures and
  // Radiance .hdr environments (JPEG decoding may differ from libjpeg's by a level).
  static const OpenImageIoFormats formats{read_any, jpeg_header, decode_jpeg};
  return formats;
}

}  // namespace kit
