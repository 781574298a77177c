#include "base/safe_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "base/error.h"

namespace fs = std::filesystem;

namespace kit {

namespace {

// An opened regular file: the descriptor (closed on every path out) and its fstat.
struct OpenedFile {
  int fd = -1;
  struct stat st {};
  std::string shown;
  OpenedFile() = default;
  OpenedFile(const OpenedFile&) = delete;
  OpenedFile& operator=(const OpenedFile&) = delete;
  ~OpenedFile() {
    if (fd >= 0) ::close(fd);
  }
};

void open_regular(const fs::path& path, const SafeOpen& how, OpenedFile& file) {
  file.shown = how.shown.empty() ? path.string() : how.shown;
  // O_NONBLOCK: opening a FIFO for reading would otherwise wait for a writer forever.
  file.fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC | (how.follow_link ? 0 : O_NOFOLLOW));
  if (file.fd < 0) {
    if (errno == ELOOP) throw Error(file.shown + ": is a symbolic link (not followed)");
    if (errno == ENOENT) throw Error(file.shown + ": file not found");
    throw Error(file.shown + ": cannot open: " + std::strerror(errno));
  }
  if (::fstat(file.fd, &file.st) != 0 || !S_ISREG(file.st.st_mode)) throw Error(file.shown + ": not a regular file");
  if (how.refuse_hard_links && file.st.st_nlink > 1)
    throw Error(file.shown + ": is a hard link (the file has " + std::to_string(file.st.st_nlink) +
                " names, and the others may lie outside this folder)");
}

std::vector<unsigned char> read_opened(const OpenedFile& file, std::uintmax_t max_bytes) {
  if (static_cast<std::uintmax_t>(file.st.st_size) > max_bytes)
    throw Error(file.shown + ": " + std::to_string(file.st.st_size) + " bytes, over the " + std::to_string(max_bytes) +
                "-byte limit");
  // Exactly the size fstat gave: a file growing meanwhile is read no further.
  std::vector<unsigned char> bytes(static_cast<size_t>(file.st.st_size));
  size_t done = 0;
  while (done < bytes.size()) {
    ssize_t n = ::read(file.fd, bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) throw Error(file.shown + ": read failed: " + std::strerror(errno));
    if (n == 0) throw Error(file.shown + ": the file shrank while it was read");
    done += static_cast<size_t>(n);
  }
  return bytes;
}

}  // namespace

std::vector<unsigned char> read_regular_file(const fs::path& path, std::uintmax_t max_bytes, const SafeOpen& how) {
  OpenedFile file;
  open_regular(path, how, file);
  return read_opened(file, max_bytes);
}

std::vector<unsigned char> read_file_inside(const fs::path& path, const fs::path& folder, std::uintmax_t max_bytes) {
  SafeOpen how;
  how.refuse_hard_links = true;
  OpenedFile file;
  open_regular(path, how, file);
  // Where the opened file really is: links in the folders above it are resolved too.
  std::error_code ec;
  fs::path real = fs::read_symlink("/proc/self/fd/" + std::to_string(file.fd), ec);
  fs::path root = fs::canonical(folder, ec);
  if (ec || real.empty()) throw Error(path.string() + ": cannot tell where the file lies");
  fs::path rel = real.lexically_relative(root);
  if (rel.empty() || *rel.begin() == "..")
    throw Error(path.string() + ": lies outside the scene's folder " + root.string() +
                " (a scene may only name files beside it or below it)");
  return read_opened(file, max_bytes);
}

void stream_regular_file(const fs::path& path, const std::function<void(const unsigned char*, size_t)>& sink,
                         const SafeOpen& how) {
  OpenedFile file;
  open_regular(path, how, file);
  std::vector<unsigned char> buffer(size_t{1} << 16);
  for (;;) {
    ssize_t n = ::read(file.fd, buffer.data(), buffer.size());
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) throw Error(file.shown + ": read failed: " + std::strerror(errno));
    if (n == 0) return;
    sink(buffer.data(), static_cast<size_t>(n));
  }
}

bool names_file_inside_folder(const fs::path& relative) {
  if (relative.is_absolute() || relative.has_root_name() || relative.has_root_directory()) return false;
  for (const auto& part : relative)
    if (part == "..") return false;
  return true;
}

}  // namespace kit
