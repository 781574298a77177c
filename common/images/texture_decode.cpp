#include "images/texture_decode.h"

#include "base/error.h"
#include "images/image_codecs.h"
#include "images/openimageio_formats.h"

namespace kit {

namespace {

bool is_jpeg(const unsigned char* bytes, size_t size) {
  return size >= 3 && bytes[0] == 0xFF && bytes[1] == 0xD8 && bytes[2] == 0xFF;
}

// glTF allows PNG and JPEG; OBJ files are held to the same two. PNG is read by libpng
// here, JPEG by OpenImageIO (loaded the first time a scene has one).
void require_png_or_jpeg(const unsigned char* bytes, size_t size, const std::string& what) {
  if (!is_png(bytes, size) && !is_jpeg(bytes, size)) throw Error(what + " is neither PNG nor JPEG");
}

}  // namespace

TextureHeader read_texture_header(const unsigned char* bytes, size_t size, const std::string& what) {
  require_png_or_jpeg(bytes, size, what);
  if (is_jpeg(bytes, size)) return openimageio_formats().jpeg_header(bytes, size, what);
  const PngHeader header = read_png_header(bytes, size, what);
  check_texture_size(header.width, header.height, header.channels, what);
  return {header.width, header.height};
}

ImageRgba8 decode_texture_image(const unsigned char* bytes, size_t size, const std::string& what) {
  require_png_or_jpeg(bytes, size, what);
  Pixels8 in = is_jpeg(bytes, size) ? openimageio_formats().decode_jpeg(bytes, size, what)
                                          : decode_png8(bytes, size, what, kMaxTextureSide);
  check_texture_size(in.width, in.height, in.channels, what);
  const size_t pixels = static_cast<size_t>(in.width) * static_cast<size_t>(in.height);
  const int n = in.channels;
  ImageRgba8 out;
  out.width = in.width;
  out.height = in.height;
  if (n == 4) {  // already RGBA: no second copy of a large texture
    out.pixels = std::move(in.pixels);
    return out;
  }
  out.pixels.resize(pixels * 4);
  for (size_t p = 0; p < pixels; ++p) {
    const unsigned char* s = &in.pixels[p * static_cast<size_t>(n)];
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
