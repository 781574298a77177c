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

// Copies the generated kit scene `name` ("default", "sphere", ...) file by file into
// `dir` (created; files already there replaced) and returns the copy's .gltf: a scene
// a test may break or re-encode without touching the build's.
std::filesystem::path copy_scene(const std::string& name, const std::filesystem::path& dir);

}  // namespace kit::test
