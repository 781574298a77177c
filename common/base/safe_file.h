#pragma once
// Reading files that come from someone else (a student's scene, its buffers and
// images, a submission's lab files): regular files only, never through a
// symbolic link in the last component, opened without blocking (a FIFO named as
// a buffer cannot hang the reader), checked with fstat on the opened descriptor
// (so what is checked is what is read), and size-limited before reading.
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

namespace kit {

// How a file is opened and named.
struct SafeOpen {
  std::string shown;               // how messages name the file ("": its path)
  bool refuse_hard_links = false;  // refuse a regular file with more than one name (st_nlink > 1):
                                   // its other names may lie anywhere on the file system
  bool follow_link = false;        // follow a symbolic link in the last component: only for a path
                                   // the person running the tool named (a submission's own .zip)
};

// The file's bytes. Throws kit::Error naming the file when it is missing, not a
// regular file, a symbolic link, a hard link (when refused), larger than
// `max_bytes`, or unreadable.
std::vector<unsigned char> read_regular_file(const std::filesystem::path& path, std::uintmax_t max_bytes,
                                             const SafeOpen& how = {});

// The same, and the file must lie inside `folder` (after resolving every link in
// the path; hard links are refused, since the path a hard link was opened by says
// nothing about where its other names lie): a scene's buffers and images may not
// reach out of the scene's folder.
std::vector<unsigned char> read_file_inside(const std::filesystem::path& path, const std::filesystem::path& folder,
                                            std::uintmax_t max_bytes);

// Whether a path a scene file names (a glTF URI, an OBJ's mtllib or texture) stays
// in the scene's folder by its spelling: relative and without a ".." part. Loaders
// refuse the others with the element's name; read_file_inside checks the file itself
// again, links included.
bool names_file_inside_folder(const std::filesystem::path& relative);

// Opens the file under the same rules and hands its bytes to `sink` in chunks,
// however large it is (hashing). Throws kit::Error as read_regular_file does.
void stream_regular_file(const std::filesystem::path& path,
                         const std::function<void(const unsigned char*, size_t)>& sink, const SafeOpen& how = {});

}  // namespace kit
