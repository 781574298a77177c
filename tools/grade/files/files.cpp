#include "files/files.h"

#include <nlohmann/json.hpp>

#include <unistd.h>

#include <cstdint>
#include <cstring>
#include <fstream>

#include "base/error.h"

namespace fs = std::filesystem;

namespace kit::grade {

namespace {

constexpr char kRawMagic[8] = {'K', 'I', 'T', 'R', 'A', 'W', '1', '\0'};
// Larger than any render the grader makes: a corrupt header cannot make the parent allocate gigabytes.
constexpr int kMaxRawDimension = 8192;

}  // namespace

void write_file_atomic(const fs::path& path, const std::string& text) {
  fs::path temp = path;
  temp += ".tmp-" + std::to_string(getpid());
  {
    std::ofstream out(temp, std::ios::binary);
    out << text;
    out.flush();
    if (!out) throw Error(path.string() + ": cannot write");
  }
  fs::rename(temp, path);
}

std::string json_text(const nlohmann::json& doc) {
  // File names and logs from a submission need not be UTF-8: invalid bytes become
  // U+FFFD instead of making dump() throw, so the file is always valid JSON.
  return doc.dump(1, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
}

void write_text(const fs::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
}

std::string read_tail(const fs::path& path, size_t max_bytes) {
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) return "";
  std::streamoff size = in.tellg();
  std::streamoff start = size > static_cast<std::streamoff>(max_bytes) ? size - static_cast<std::streamoff>(max_bytes) : 0;
  in.seekg(start);
  std::string text(static_cast<size_t>(size - start), '\0');
  in.read(text.data(), static_cast<std::streamsize>(text.size()));
  return text;
}

std::string trimmed(std::string text) {
  while (!text.empty() && (text.back() == '\n' || text.back() == ' ')) text.pop_back();
  return text;
}

bool writable_folder(const fs::path& dir, std::string* why) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec || !fs::is_directory(dir)) {
    *why = dir.string() + ": cannot create the output folder" + (ec ? " (" + ec.message() + ")" : "");
    return false;
  }
  fs::path probe = dir / (".kit-grade-probe-" + std::to_string(getpid()));
  std::ofstream(probe) << "";
  bool ok = fs::exists(probe);
  fs::remove(probe, ec);
  if (!ok) *why = dir.string() + ": cannot write in the output folder";
  return ok;
}

fs::path raw_image_path(const fs::path& dir, const std::string& render_id) { return dir / (render_id + ".raw"); }

void write_raw_image(const fs::path& path, const Image& image) {
  std::ofstream out(path, std::ios::binary);
  int32_t header[3] = {image.width, image.height, image.channels};
  out.write(kRawMagic, sizeof kRawMagic);
  out.write(reinterpret_cast<const char*>(header), sizeof header);
  out.write(reinterpret_cast<const char*>(image.pixels.data()), static_cast<std::streamsize>(image.pixels.size() * sizeof(float)));
  if (!out) throw Error(path.string() + ": cannot write");
}

Image read_raw_image(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(path.filename().string() + ": the renderer wrote no image");
  char magic[sizeof kRawMagic];
  int32_t header[3] = {0, 0, 0};
  in.read(magic, sizeof magic);
  in.read(reinterpret_cast<char*>(header), sizeof header);
  if (!in || std::memcmp(magic, kRawMagic, sizeof magic) != 0 || header[0] < 1 || header[1] < 1 || header[2] < 1 ||
      header[0] > kMaxRawDimension || header[1] > kMaxRawDimension || header[2] > 4)
    throw Error(path.filename().string() + ": not a raw image from the renderer");
  Image image(header[0], header[1], header[2]);
  in.read(reinterpret_cast<char*>(image.pixels.data()), static_cast<std::streamsize>(image.pixels.size() * sizeof(float)));
  if (!in) throw Error(path.filename().string() + ": the image is incomplete");
  return image;
}

}  // namespace kit::grade
