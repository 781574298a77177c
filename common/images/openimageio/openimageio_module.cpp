// libkit_openimageio.so: the kit's calls into OpenImageIO, loaded by
// openimageio_formats() the first time a file is in a format other than PNG or EXR.
// It links OpenImageIO and no part of kitcore (only its headers' inline types).
#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>

#include <memory>

#include "base/error.h"
#include "images/openimageio_formats.h"

namespace {

using kit::Error;

kit::Image read_any(const std::string& path, int max_width, int max_height) {
  auto in = OIIO::ImageInput::open(path);
  if (!in) throw Error(path + ": cannot read the image: " + OIIO::geterror());
  const OIIO::ImageSpec& spec = in->spec();
  if (spec.width < 1 || spec.height < 1 || spec.width > max_width || spec.height > max_height)
    throw Error(path + ": the image is " + std::to_string(spec.width) + "x" + std::to_string(spec.height) +
                " pixels (at most " + std::to_string(max_width) + "x" + std::to_string(max_height) + ")");
  if (spec.nchannels < 1 || spec.nchannels > 4)
    throw Error(path + ": the image has " + std::to_string(spec.nchannels) + " channels (at most 4)");
  kit::Image image(spec.width, spec.height, spec.nchannels);
  if (!in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, image.pixels.data()))
    throw Error(path + ": cannot decode the image: " + in->geterror());
  return image;
}

// Opens JPEG bytes and checks the header; `reader` must outlive the result.
std::unique_ptr<OIIO::ImageInput> open_jpeg(OIIO::Filesystem::IOMemReader& reader, const std::string& what) {
  OIIO::ImageSpec config;
  void* proxy = &reader;
  config.attribute("oiio:ioproxy", OIIO::TypeDesc::PTR, &proxy);
  auto in = OIIO::ImageInput::open("image.jpg", &config, &reader);
  if (!in) throw Error(what + " could not be decoded: " + OIIO::geterror());
  kit::check_texture_size(in->spec().width, in->spec().height, in->spec().nchannels, what);
  return in;
}

kit::TextureHeader jpeg_header(const unsigned char* bytes, size_t size, const std::string& what) {
  OIIO::Filesystem::IOMemReader reader(const_cast<unsigned char*>(bytes), size);
  auto in = open_jpeg(reader, what);
  return {in->spec().width, in->spec().height};
}

kit::Pixels8 decode_jpeg(const unsigned char* bytes, size_t size, const std::string& what) {
  OIIO::Filesystem::IOMemReader reader(const_cast<unsigned char*>(bytes), size);
  auto in = open_jpeg(reader, what);
  const OIIO::ImageSpec& spec = in->spec();
  kit::Pixels8 out;
  out.width = spec.width;
  out.height = spec.height;
  out.channels = spec.nchannels;
  out.pixels.resize(static_cast<size_t>(spec.width) * static_cast<size_t>(spec.height) * static_cast<size_t>(spec.nchannels));
  if (!in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::UINT8, out.pixels.data()))
    throw Error(what + ": " + in->geterror());
  return out;
}

const kit::OpenImageIoFormats kFormats = {read_any, jpeg_header, decode_jpeg};

}  // namespace

extern "C" const kit::OpenImageIoFormats* kit_openimageio_formats() { return &kFormats; }
