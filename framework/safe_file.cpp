#include "safe_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "error.h"

namespace fs = std::filesystem;

namespace kit {

namespace {

// Closes the descriptor on every path out.
struct Descriptor {
  int fd;
  ~Descriptor() {
    if (fd >= 0) ::close(fd);
  }
};

int open_regular(const fs::path& path, struct stat* st) {
  // O_NONBLOCK: opening a FIFO for reading would otherwise wait for a writer forever.
  int fd = ::open(path.c_str(), O_RDONLY | O_NOFOLLOW | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) {
    if (errno == ELOOP) throw Error(path.string() + ": is a symbolic link (not followed)");
    if (errno == ENOENT) throw Error(path.string() + ": file not found");
    throw Error(path.string() + ": cannot open: " + std::strerror(errno));
  }
  if (::fstat(fd, st) != 0 || !S_ISREG(st->st_mode)) {
    ::close(fd);
    throw Error(path.string() + ": not a regular file");
  }
  return fd;
}

std::vector<unsigned char> read_descriptor(int fd, const struct stat& st, const fs::path& path, std::uintmax_t max_bytes) {
  if (static_cast<std::uintmax_t>(st.st_size) > max_bytes)
    throw Error(path.string() + ": " + std::to_string(st.st_size) + " bytes, over the limit of " +
                std::to_string(max_bytes));
  std::vector<unsigned char> bytes(static_cast<size_t>(st.st_size));
  size_t done = 0;
  while (done < bytes.size()) {
    ssize_t n = ::read(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) throw Error(path.string() + ": read failed: " + std::strerror(errno));
    if (n == 0) throw Error(path.string() + ": the file shrank while it was read");
    done += static_cast<size_t>(n);
  }
  return bytes;
}

}  // namespace

std::vector<unsigned char> read_regular_file(const fs::path& path, std::uintmax_t max_bytes) {
  struct stat st {};
  Descriptor d{open_regular(path, &st)};
  return read_descriptor(d.fd, st, path, max_bytes);
}

std::vector<unsigned char> read_file_inside(const fs::path& path, const fs::path& folder, std::uintmax_t max_bytes) {
  struct stat st {};
  Descriptor d{open_regular(path, &st)};
  // Where the opened file really is: links in the folders above it are resolved too.
  std::error_code ec;
  fs::path real = fs::read_symlink("/proc/self/fd/" + std::to_string(d.fd), ec);
  fs::path root = fs::canonical(folder, ec);
  if (ec || real.empty()) throw Error(path.string() + ": cannot tell where the file lies");
  fs::path rel = real.lexically_relative(root);
  if (rel.empty() || *rel.begin() == "..")
    throw Error(path.string() + ": lies outside the scene's folder " + root.string() +
                " (a scene may only name files beside it or below it)");
  return read_descriptor(d.fd, st, path, max_bytes);
}

}  // namespace kit
