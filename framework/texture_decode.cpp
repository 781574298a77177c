#include "texture_decode.h"

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <memory>
#include <vector>

#include "error.h"

namespace kit {

namespace {

// Opens PNG or JPEG bytes and checks the header; `reader` must outlive the result.
std::unique_ptr<OIIO::ImageInput> open_texture(OIIO::Filesystem::IOMemReader& reader, const unsigned char* bytes,
                                               size_t size, const std::string& what) {
  // glTF allows PNG and JPEG; OBJ files are held to the same two.
  const bool png = size >= 8 && bytes[0] == 0x89 && bytes[1] == 'P' && bytes[2] == 'N' && bytes[3] == 'G';
  const bool jpeg = size >= 3 && bytes[0] == 0xFF && bytes[1] == 0xD8 && bytes[2] == 0xFF;
  if (!png && !jpeg) throw Error(what + " is neither PNG nor JPEG");
  // A PNG's colour is stored unpremultiplied, as glTF and MTL mean it; OIIO would
  // multiply it by alpha on read (RGB 200 at alpha 0.5 would become 100) unless told
  // not to. With a configuration, the reader takes its memory proxy from it too.
  OIIO::ImageSpec config;
  config.attribute("oiio:UnassociatedAlpha", 1);
  void* proxy = &reader;
  config.attribute("oiio:ioproxy", OIIO::TypeDesc::PTR, &proxy);
  auto in = OIIO::ImageInput::open(png ? "image.png" : "image.jpg", &config, &reader);
  if (!in) throw Error(what + " could not be decoded: " + OIIO::geterror());
  const OIIO::ImageSpec& spec = in->spec();
  if (spec.width <= 0 || spec.height <= 0 || spec.width > kMaxTextureSide || spec.height > kMaxTextureSide ||
      spec.nchannels < 1 || spec.nchannels > 4)
    throw Error(what + " is " + std::to_string(spec.width) + "x" + std::to_string(spec.height) + " with " +
                std::to_string(spec.nchannels) + " channels (at most " + std::to_string(kMaxTextureSide) +
                " pixels a side and 4 channels)");
  return in;
}

}  // namespace

TextureHeader read_texture_header(const unsigned char* bytes, size_t size, const std::string& what) {
  OIIO::Filesystem::IOMemReader reader(const_cast<unsigned char*>(bytes), size);
  auto in = open_texture(reader, bytes, size, what);
  return {in->spec().width, in->spec().height};
}

ImageRgba8 decode_texture_image(const unsigned char* bytes, size_t size, const std::string& what) {
  OIIO::Filesystem::IOMemReader reader(const_cast<unsigned char*>(bytes), size);
  auto in = open_texture(reader, bytes, size, what);
  const OIIO::ImageSpec& spec = in->spec();
  const size_t pixels = static_cast<size_t>(spec.width) * static_cast<size_t>(spec.height);
  const int n = spec.nchannels;
  ImageRgba8 out;
  out.width = spec.width;
  out.height = spec.height;
  out.pixels.resize(pixels * 4);
  // Read a strip of rows at a time, in the file's own layout, into a small buffer, and
  // spread each strip into RGBA. Asked for its native format (TypeUnknown: 8-bit files),
  // OIIO reads straight into the buffer; asked for a conversion (16-bit PNG to 8 bits)
  // it allocates a buffer of up to 64 MiB for every call, so such a file is read whole.
  const bool native_8_bit = spec.format == OIIO::TypeDesc::UINT8;
  const OIIO::TypeDesc read_as = native_8_bit ? OIIO::TypeDesc(OIIO::TypeDesc::UNKNOWN) : OIIO::TypeDesc::UINT8;
  constexpr int kStripRows = 64;
  const int strip_rows = native_8_bit ? std::min(kStripRows, spec.height) : spec.height;
  const size_t row_bytes = static_cast<size_t>(spec.width) * static_cast<size_t>(n);
  std::vector<unsigned char> strip(row_bytes * static_cast<size_t>(strip_rows));
  for (int first = 0; first < spec.height; first += strip_rows) {
    const int rows = std::min(strip_rows, spec.height - first);
    if (!in->read_scanlines(0, 0, spec.y + first, spec.y + first + rows, 0, 0, n, read_as, strip.data()))
      throw Error(what + ": " + in->geterror());
    const size_t strip_pixels = static_cast<size_t>(rows) * static_cast<size_t>(spec.width);
    unsigned char* d = &out.pixels[static_cast<size_t>(first) * static_cast<size_t>(spec.width) * 4];
    for (size_t p = 0; p < strip_pixels; ++p, d += 4) {
      const unsigned char* s = &strip[p * static_cast<size_t>(n)];
      d[0] = s[0];
      d[1] = n >= 3 ? s[1] : s[0];
      d[2] = n >= 3 ? s[2] : s[0];
      d[3] = n == 4 ? s[3] : n == 2 ? s[1] : 255;
    }
  }
  return out;
}

ImageRgba8 decode_scene_image(const SceneImage& image) {
  if (image.encoded.empty()) return image.decoded;
  return decode_texture_image(image.encoded.data(), image.encoded.size(), image.what);
}

}  // namespace kit
