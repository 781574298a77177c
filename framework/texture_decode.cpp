#include "texture_decode.h"

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>

#include <memory>

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
  std::vector<unsigned char> src(pixels * static_cast<size_t>(n));
  if (!in->read_image(0, 0, 0, n, OIIO::TypeDesc::UINT8, src.data())) throw Error(what + ": " + in->geterror());
  ImageRgba8 out;
  out.width = spec.width;
  out.height = spec.height;
  out.pixels.resize(pixels * 4);
  for (size_t p = 0; p < pixels; ++p) {
    const unsigned char* s = &src[p * static_cast<size_t>(n)];
    unsigned char* d = &out.pixels[p * 4];
    d[0] = s[0];
    d[1] = n >= 3 ? s[1] : s[0];
    d[2] = n >= 3 ? s[2] : s[0];
    d[3] = n == 4 ? s[3] : n == 2 ? s[1] : 255;
  }
  return out;
}

ImageRgba8 decode_scene_image(const SceneImage& image) {
  if (image.encoded.empty()) return image.decoded;
  return decode_texture_image(image.encoded.data(), image.encoded.size(), image.what);
}

}  // namespace kit
