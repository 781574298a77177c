#include "images/image_codecs.h"

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>
#include <png.h>

#include <cctype>
#include <cerrno>
#include <csetjmp>
#include <cstdio>
#include <cstring>

#include "base/error.h"
#include "base/safe_file.h"
#include "base/text.h"

namespace kit {

namespace {

// libpng reports an error by calling back and never returning: the callback keeps the
// message and longjmps to the setjmp of the function that called libpng (its frames are
// C, so no destructor is skipped), which throws it as a kit::Error.
struct PngErrors {
  char message[256] = "";
};

void keep_error_and_jump(png_structp png, png_const_charp message) {
  auto* errors = static_cast<PngErrors*>(png_get_error_ptr(png));
  std::snprintf(errors->message, sizeof errors->message, "%s", message);
  png_longjmp(png, 1);
}

void ignore_warning(png_structp, png_const_charp) {}

struct MemoryReader {
  const unsigned char* bytes;
  size_t size, offset;
};

void read_from_memory(png_structp png, png_bytep out, png_size_t count) {
  auto* reader = static_cast<MemoryReader*>(png_get_io_ptr(png));
  if (count > reader->size - reader->offset) png_error(png, "the file ends early");
  std::memcpy(out, reader->bytes + reader->offset, count);
  reader->offset += count;
}

// A png_struct and its info for reading, freed on every way out.
struct PngRead {
  PngErrors errors;
  png_structp png = nullptr;
  png_infop info = nullptr;
  MemoryReader reader;
  PngRead(const unsigned char* bytes, size_t size) : reader{bytes, size, 0} {
    png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &errors, keep_error_and_jump, ignore_warning);
    if (png) info = png_create_info_struct(png);
    if (!png || !info) {
      png_destroy_read_struct(&png, &info, nullptr);
      throw Error("out of memory for libpng");
    }
    png_set_read_fn(png, &reader, read_from_memory);
  }
  ~PngRead() { png_destroy_read_struct(&png, &info, nullptr); }
  PngRead(const PngRead&) = delete;
  PngRead& operator=(const PngRead&) = delete;
};

// Decoded rows: 8 or 16 bits a channel (16-bit samples in the machine's byte order).
struct PngPixels {
  int width = 0, height = 0, channels = 0, bits = 8;
  std::vector<unsigned char> bytes;
};

// libpng's part of read_png_header: the setjmp is here, and what it fills lives in the
// caller's frame (a local changed after setjmp would be indeterminate after the jump).
bool read_header(PngRead& r, PngHeader& header) {
  if (setjmp(png_jmpbuf(r.png))) return false;
  png_read_info(r.png, r.info);
  png_set_expand(r.png);
  png_read_update_info(r.png, r.info);
  header.width = static_cast<int>(png_get_image_width(r.png, r.info));
  header.height = static_cast<int>(png_get_image_height(r.png, r.info));
  header.channels = png_get_channels(r.png, r.info);
  return true;
}

// libpng's part of decode_png (the setjmp is here, as in read_header).
bool decode_rows(PngRead& r, PngPixels& out, std::vector<png_bytep>& rows, int max_side, bool to_8_bits) {
  if (setjmp(png_jmpbuf(r.png))) return false;
  // Refused while the header is read, before any row is allocated.
  png_set_user_limits(r.png, static_cast<png_uint_32>(max_side), static_cast<png_uint_32>(max_side));
  png_read_info(r.png, r.info);
  png_set_expand(r.png);  // palette to RGB, grey under 8 bits to 8, tRNS to alpha
  if (to_8_bits) png_set_scale_16(r.png);
  else png_set_swap(r.png);  // 16-bit samples are big-endian in the file
  png_set_interlace_handling(r.png);
  png_read_update_info(r.png, r.info);
  out.width = static_cast<int>(png_get_image_width(r.png, r.info));
  out.height = static_cast<int>(png_get_image_height(r.png, r.info));
  out.channels = png_get_channels(r.png, r.info);
  out.bits = png_get_bit_depth(r.png, r.info);
  const size_t row_bytes = png_get_rowbytes(r.png, r.info);
  // Both sides are at most max_side (png_set_user_limits), so the product fits.
  if (row_bytes != static_cast<size_t>(out.width) * static_cast<size_t>(out.channels) * static_cast<size_t>(out.bits / 8))
    png_error(r.png, "unexpected row size");
  out.bytes.resize(row_bytes * static_cast<size_t>(out.height));
  rows.resize(static_cast<size_t>(out.height));
  for (size_t y = 0; y < rows.size(); ++y) rows[y] = out.bytes.data() + y * row_bytes;
  png_read_image(r.png, rows.data());
  return true;
}

PngPixels decode_png(const unsigned char* bytes, size_t size, const std::string& what, int max_side, bool to_8_bits) {
  if (!is_png(bytes, size)) throw Error(what + " is not a PNG");
  PngRead r(bytes, size);
  PngPixels out;
  std::vector<png_bytep> rows;
  if (!decode_rows(r, out, rows, max_side, to_8_bits)) throw Error(what + " could not be decoded: " + r.errors.message);
  return out;
}

// libpng's part of write_png (the setjmp is here, as in decode_rows).
bool write_rows(png_structp png, png_infop info, std::FILE* file, const Image& image, PngEffort effort,
                std::vector<unsigned char>& row) {
  if (setjmp(png_jmpbuf(png))) return false;
  static const int kColourTypes[] = {PNG_COLOR_TYPE_GRAY, PNG_COLOR_TYPE_GRAY_ALPHA, PNG_COLOR_TYPE_RGB,
                                     PNG_COLOR_TYPE_RGB_ALPHA};
  png_init_io(png, file);
  png_set_IHDR(png, info, static_cast<png_uint_32>(image.width), static_cast<png_uint_32>(image.height), 8,
               kColourTypes[image.channels - 1], PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  if (effort == PngEffort::Fastest) {
    png_set_compression_level(png, 1);
    png_set_filter(png, PNG_FILTER_TYPE_BASE, PNG_FILTER_SUB);
  }
  png_write_info(png, info);
  for (int y = 0; y < image.height; ++y) {
    const float* values = image.pixels.data() + static_cast<size_t>(y) * row.size();
    for (size_t i = 0; i < row.size(); ++i) row[i] = to_unorm8(values[i]);
    png_write_row(png, row.data());
  }
  png_write_end(png, info);
  return true;
}

// The channels read_exr takes from a file, in order.
std::vector<std::string> exr_channels(const Imf::ChannelList& list, const std::string& path) {
  std::vector<std::string> names;
  for (const char* name : {"R", "G", "B", "A"})
    if (list.findChannel(name)) names.push_back(name);
  std::vector<std::string> all;
  for (auto it = list.begin(); it != list.end(); ++it) all.push_back(it.name());
  if (names.empty() && all.size() == 1) names = all;
  if (names.empty()) {
    std::string listed;
    for (const std::string& n : all) listed += (listed.empty() ? "" : ", ") + n;
    throw Error(path + ": an EXR with channels " + (listed.empty() ? "(none)" : listed) +
                " (the kit reads R, G, B and A, or a single grey channel)");
  }
  for (const std::string& n : names)
    if (list.findChannel(n.c_str())->xSampling != 1 || list.findChannel(n.c_str())->ySampling != 1)
      throw Error(path + ": channel " + n + " is subsampled (the kit reads full-resolution channels only)");
  return names;
}

// A frame buffer over `image` for the window `window` (OpenEXR addresses pixels by
// their window coordinates, so the base is moved back by the window's origin).
template <typename Box>
Imf::FrameBuffer frame_buffer(Image& image, const std::vector<std::string>& names, const Box& window) {
  Imf::FrameBuffer buffer;
  const size_t x_stride = sizeof(float) * static_cast<size_t>(image.channels);
  const size_t y_stride = x_stride * static_cast<size_t>(image.width);
  for (size_t c = 0; c < names.size(); ++c) {
    char* first = reinterpret_cast<char*>(image.pixels.data() + c);
    char* base = first - static_cast<ptrdiff_t>(window.min.x) * static_cast<ptrdiff_t>(x_stride) -
                 static_cast<ptrdiff_t>(window.min.y) * static_cast<ptrdiff_t>(y_stride);
    buffer.insert(names[c].c_str(), Imf::Slice(Imf::FLOAT, base, x_stride, y_stride));
  }
  return buffer;
}

}  // namespace

bool has_extension(const std::string& path, const std::string& extension) {
  return path.size() >= extension.size() && lower_case(path.substr(path.size() - extension.size())) == extension;
}

bool is_png(const unsigned char* bytes, size_t size) { return size >= 8 && png_sig_cmp(bytes, 0, 8) == 0; }

PngHeader read_png_header(const unsigned char* bytes, size_t size, const std::string& what) {
  if (!is_png(bytes, size)) throw Error(what + " is not a PNG");
  PngRead r(bytes, size);
  PngHeader header;
  if (!read_header(r, header)) throw Error(what + " could not be decoded: " + r.errors.message);
  return header;
}

Pixels8 decode_png8(const unsigned char* bytes, size_t size, const std::string& what, int max_side) {
  PngPixels decoded = decode_png(bytes, size, what, max_side, true);
  return {decoded.width, decoded.height, decoded.channels, std::move(decoded.bytes)};
}

Image read_png(const std::string& path) {
  // The largest a PNG within the side limit holds uncompressed (16-bit RGBA): 2 GiB.
  constexpr std::uintmax_t kMaxPngBytes = static_cast<std::uintmax_t>(kMaxImageSide) * kMaxImageSide * 8;
  SafeOpen how;
  how.follow_link = true;  // a path the person running the tool named
  const std::vector<unsigned char> bytes = read_regular_file(path, kMaxPngBytes, how);
  const PngPixels decoded = decode_png(bytes.data(), bytes.size(), path, kMaxImageSide, false);
  Image image(decoded.width, decoded.height, decoded.channels);
  if (decoded.bits == 16) {
    for (size_t i = 0; i < image.pixels.size(); ++i) {
      uint16_t v;
      std::memcpy(&v, decoded.bytes.data() + 2 * i, sizeof v);
      image.pixels[i] = static_cast<float>(v) * (1.0f / 65535.0f);
    }
  } else {
    for (size_t i = 0; i < image.pixels.size(); ++i) image.pixels[i] = static_cast<float>(decoded.bytes[i]) * (1.0f / 255.0f);
  }
  return image;
}

void write_png(const std::string& path, const Image& image, PngEffort effort) {
  if (image.channels < 1 || image.channels > 4 || image.width < 1 || image.height < 1)
    throw Error(path + ": cannot write a " + std::to_string(image.width) + "x" + std::to_string(image.height) + " image with " +
                std::to_string(image.channels) + " channels as PNG");
  std::FILE* file = std::fopen(path.c_str(), "wb");
  if (!file) throw Error(path + ": cannot open for writing: " + std::strerror(errno));
  PngErrors errors;
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &errors, keep_error_and_jump, ignore_warning);
  png_infop info = png ? png_create_info_struct(png) : nullptr;
  std::vector<unsigned char> row(static_cast<size_t>(image.width) * static_cast<size_t>(image.channels));
  const bool written = png && info && write_rows(png, info, file, image, effort, row);
  png_destroy_write_struct(&png, &info);
  const bool closed = std::fclose(file) == 0;
  if (!written || !closed)
    throw Error(path + ": write failed" + (errors.message[0] ? std::string(": ") + errors.message : std::string()));
}

Image read_exr(const std::string& path, int max_width, int max_height) {
  try {
    // No worker threads: kit-grade forks its render workers while it reads (and the
    // grader's images are small).
    Imf::InputFile file(path.c_str(), 0);
    const auto& window = file.header().dataWindow();
    const long width = static_cast<long>(window.max.x) - window.min.x + 1;
    const long height = static_cast<long>(window.max.y) - window.min.y + 1;
    if (width < 1 || height < 1 || width > max_width || height > max_height)
      throw Error(path + ": the image is " + std::to_string(width) + "x" + std::to_string(height) + " pixels (at most " +
                  std::to_string(max_width) + "x" + std::to_string(max_height) + ")");
    const std::vector<std::string> names = exr_channels(file.header().channels(), path);
    Image image(static_cast<int>(width), static_cast<int>(height), static_cast<int>(names.size()));
    file.setFrameBuffer(frame_buffer(image, names, window));
    file.readPixels(window.min.y, window.max.y);
    return image;
  } catch (const Error&) {
    throw;
  } catch (const std::exception& e) {  // OpenEXR's exceptions (Iex) are std::exceptions
    throw Error(path + ": cannot read the EXR: " + e.what());
  }
}

void write_exr(const std::string& path, const Image& image) {
  if (image.channels < 1 || image.channels > 4 || image.width < 1 || image.height < 1)
    throw Error(path + ": cannot write a " + std::to_string(image.width) + "x" + std::to_string(image.height) + " image with " +
                std::to_string(image.channels) + " channels as EXR");
  static const char* const kRgba[] = {"R", "G", "B", "A"};
  std::vector<std::string> names;
  if (image.channels == 1) names = {"Y"};
  else names.assign(kRgba, kRgba + image.channels);
  try {
    Imf::Header header(image.width, image.height);
    header.compression() = Imf::ZIP_COMPRESSION;
    for (const std::string& name : names) header.channels().insert(name.c_str(), Imf::Channel(Imf::FLOAT));
    Imf::OutputFile file(path.c_str(), header, 0);
    Image& pixels = const_cast<Image&>(image);  // OpenEXR's Slice takes a char*; writing only reads it
    file.setFrameBuffer(frame_buffer(pixels, names, header.dataWindow()));
    file.writePixels(image.height);
  } catch (const std::exception& e) {
    throw Error(path + ": cannot write the EXR: " + e.what());
  }
}

}  // namespace kit
