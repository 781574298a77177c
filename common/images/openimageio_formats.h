#pragma once
// OpenImageIO, for the formats beyond PNG and EXR (image_codecs.h): JPEG textures, and
// images and environments in any format it reads (Radiance .hdr, TIFF, ...). It is
// called through a module of the kit's own (libkit_openimageio.so, built beside the
// programs, common/images/openimageio/) that is loaded the first time a file needs it:
// linked into a program, OpenImageIO's ~260 shared libraries cost 0.2 s and 130 MB
// at every start, a fifth of grading one submission, which reads PNG and EXR alone.
#include <cstddef>
#include <string>

#include "images/image_codecs.h"
#include "images/texture_decode.h"

namespace kit {

struct OpenImageIoFormats {
  // Any image file OpenImageIO reads, as floats, with at most `max_width` x `max_height`
  // pixels (refused from the header, before the pixels are read). Throws kit::Error
  // naming the file.
  Image (*read_image)(const std::string& path, int max_width, int max_height);
  // JPEG bytes: the header alone, or the pixels as stored (1 or 3 channels), refused
  // over kMaxTextureSide a side. Throws kit::Error starting with `what`.
  TextureHeader (*jpeg_header)(const unsigned char* bytes, size_t size, const std::string& what);
  Pixels8 (*decode_jpeg)(const unsigned char* bytes, size_t size, const std::string& what);
};

// The module's functions, loading it on first use (from any thread). Throws kit::Error
// saying what is missing when it cannot be loaded.
const OpenImageIoFormats& openimageio_formats();

}  // namespace kit

// The module's one entry point, looked up by name after dlopen.
extern "C" const kit::OpenImageIoFormats* kit_openimageio_formats();
