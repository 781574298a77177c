#pragma once
// File helpers for tests that write their own fixtures (shader folders, broken scenes).
#include <filesystem>
#include <string>

namespace kit::test {

// The whole file as bytes. Throws std::runtime_error (a test failure) when it cannot be read.
std::string read_file(const std::filesystem::path& path);

// Writes `bytes` to `path`, replacing the file and creating missing parent folders.
// Throws std::runtime_error when it cannot be written.
void write_file(const std::filesystem::path& path, const std::string& bytes);

}  // namespace kit::test
