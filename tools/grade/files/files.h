#pragma once
// The grader's file helpers: whole files written, the end of a log read, JSON as the grader
// writes it, the raw float images a render worker hands the grader, and an output folder
// checked before a run writes there.
#include <cstddef>
#include <filesystem>
#include <string>

#include <nlohmann/json_fwd.hpp>

#include "images/image_io.h"

namespace kit::grade {

// `text` as the whole of `path`, written to a temporary file first and renamed, so a
// reader never sees half a file. Throws kit::Error when it cannot be written.
void write_file_atomic(const std::filesystem::path& path, const std::string& text);
// `text` as the whole of `path`, with no check: what a render worker leaves for the grader,
// which says what is missing when a file is not there.
void write_text(const std::filesystem::path& path, const std::string& text);
// A JSON document as text; bytes that are not UTF-8 become U+FFFD (never throws on them).
std::string json_text(const nlohmann::json& doc);

// The last `max_bytes` of a (log) file, or "" when unreadable.
std::string read_tail(const std::filesystem::path& path, size_t max_bytes);
// `text` without the newlines and spaces it ends with.
std::string trimmed(std::string text);

// Creates `dir` and checks that files can be written in it; else false, with why.
bool writable_folder(const std::filesystem::path& dir, std::string* why);

// Raw float images between a render worker and the grader (not an image file format): the
// 8 bytes "KITRAW1\0", width, height and channels as int32, then the floats.
void write_raw_image(const std::filesystem::path& path, const Image& image);
Image read_raw_image(const std::filesystem::path& path);  // throws kit::Error
std::filesystem::path raw_image_path(const std::filesystem::path& dir, const std::string& render_id);

}  // namespace kit::grade
