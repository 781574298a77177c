#pragma once
// Reading files that come from someone else (a student's scene, its buffers and
// images): regular files only, never through a symbolic link in the last
// component, opened without blocking (a FIFO named as a buffer cannot hang the
// reader), checked on the opened descriptor, and size-limited before reading.
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace kit {

// The file's bytes. Throws kit::Error naming `path` when it is missing, not a
// regular file, a symbolic link, larger than `max_bytes`, or unreadable.
std::vector<unsigned char> read_regular_file(const std::filesystem::path& path, std::uintmax_t max_bytes);

// The same, and the file must lie inside `folder` (after resolving every link in
// the path): a scene's buffers and images may not reach out of the scene's folder.
std::vector<unsigned char> read_file_inside(const std::filesystem::path& path, const std::filesystem::path& folder,
                                            std::uintmax_t max_bytes);

}  // namespace kit
