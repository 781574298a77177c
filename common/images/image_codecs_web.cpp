// The browser build's image codecs (KIT_WEB; common/CMakeLists.txt compiles this file
// there instead of image_codecs.cpp and openimageio_formats.cpp): libpng, OpenEXR and
// OpenImageIO have no WebAssembly build among Debian's packages, and emscripten's ports
// of them download their sources. PNG, JPEG and Radiance .hdr are decoded by stb_image
// (Debian's libstb-dev, header only); OpenEXR and writing images are refused by name.
#include "images/image_codecs.h"
#include "images/openimageio_formats.h"

#include <algorithm>
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

void write_png(const std::string& path, const Image&, PngEffort) {
  throw Error(path + ": the browser build writes no image files (it shows them in its canvas)");
}

Image read_exr(const std::string& path, int, int) {
  throw Error(path + ": OpenEXR is not in the browser build (Debian has no WebAssembly build of it); use a "
              "Radiance .hdr or a PNG");
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
