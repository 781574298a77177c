#include "shader_source.h"

#include <algorithm>
#include <fstream>
#include <regex>
#include <sstream>

#include "error.h"

namespace fs = std::filesystem;

namespace kit {

namespace {

constexpr int kMaxIncludeDepth = 16;
const std::string kUtf8ByteOrderMark = "\xEF\xBB\xBF";

bool valid_utf8(const std::string& s, size_t* bad_offset) {
  for (size_t i = 0; i < s.size();) {
    unsigned char c = static_cast<unsigned char>(s[i]);
    int extra = c < 0x80 ? 0 : (c >> 5) == 0x6 ? 1 : (c >> 4) == 0xE ? 2 : (c >> 3) == 0x1E ? 3 : -1;
    bool ok = extra >= 0 && i + extra < s.size();
    for (int k = 1; ok && k <= extra; ++k) ok = (static_cast<unsigned char>(s[i + k]) >> 6) == 0x2;
    if (!ok) {
      *bad_offset = i;
      return false;
    }
    i += extra + 1;
  }
  return true;
}

bool is_inside(const fs::path& file, const fs::path& folder) {
  auto f = file.begin();
  for (auto d = folder.begin(); d != folder.end(); ++d, ++f) {
    if (f == file.end() || *f != *d) return false;
  }
  return true;
}

std::string trim(const std::string& s) {
  size_t b = s.find_first_not_of(" \t\r");
  if (b == std::string::npos) return "";
  size_t e = s.find_last_not_of(" \t\r");
  return s.substr(b, e - b + 1);
}

}  // namespace

bool is_plain_shader_name(const std::string& name) {
  if (name.empty() || name.size() > 128 || name[0] == '.') return false;
  for (char c : name) {
    bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
              c == '_' || c == '-' || c == '.';
    if (!ok) return false;
  }
  return name.find("..") == std::string::npos;
}

std::string read_shader_text(const fs::path& path, const std::string& display) {
  std::error_code ec;
  auto size = fs::file_size(path, ec);
  if (ec) throw Error(display + ": cannot read file (" + ec.message() + ")");
  if (size > kMaxShaderFileBytes)
    throw Error(display + ": file is " + std::to_string(size) + " bytes, over the " +
                std::to_string(kMaxShaderFileBytes) + "-byte limit for a shader");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(display + ": cannot open file");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  // A UTF-8 byte-order mark (some Windows editors write one) is not part of the text.
  if (text.compare(0, kUtf8ByteOrderMark.size(), kUtf8ByteOrderMark) == 0) text.erase(0, kUtf8ByteOrderMark.size());
  if (text.find_first_not_of(" \t\r\n") == std::string::npos)
    throw Error(display + ": file is empty");
  if (text.find('\0') != std::string::npos)
    throw Error(display + ": file holds binary data (a NUL byte), not shader text");
  size_t bad = 0;
  if (!valid_utf8(text, &bad))
    throw Error(display + ": file is not UTF-8 text (invalid byte at offset " + std::to_string(bad) + ")");
  return text;
}

ShaderLibrary::ShaderLibrary(std::vector<ShaderFolder> folders) : folders_(std::move(folders)) {}

fs::path ShaderLibrary::locate(const std::string& name, std::string* display) const {
  if (!is_plain_shader_name(name))
    throw Error("shader name \"" + name + "\" is refused: only plain file names inside the kit's "
                "shader folders can be loaded or included (no '/', '\\' or '..')");
  for (const auto& folder : folders_) {
    if (!folder.only.empty() && std::find(folder.only.begin(), folder.only.end(), name) == folder.only.end()) continue;
    fs::path candidate = folder.path / name;
    std::error_code ec;
    if (!fs::exists(fs::symlink_status(candidate, ec))) continue;
    std::string shown = folder.label + "/" + name;
    fs::path real = fs::weakly_canonical(candidate, ec);
    fs::path root = fs::weakly_canonical(folder.path, ec);
    if (ec || !is_inside(real, root))
      throw Error(shown + ": refused, it links outside its folder (" + real.string() + ")");
    if (!fs::is_regular_file(real, ec)) throw Error(shown + ": not a regular file");
    if (display) *display = shown;
    return real;
  }
  std::string where;
  for (const auto& f : folders_) where += (where.empty() ? "" : ", ") + f.label;
  throw Error("shader file \"" + name + "\" not found in " + (where.empty() ? "(no folders)" : where));
}

AssembledShader ShaderLibrary::assemble(const std::string& name) const {
  AssembledShader out;
  std::vector<std::string> included;
  append(name, out, included, 0, true);
  return out;
}

void ShaderLibrary::append(const std::string& name, AssembledShader& out,
                           std::vector<std::string>& included, int depth, bool top_level) const {
  if (depth > kMaxIncludeDepth) throw Error("#include nesting deeper than " + std::to_string(kMaxIncludeDepth) + " at \"" + name + "\"");
  std::string display;
  fs::path path = locate(name, &display);
  // Every file is included once per shader (like #pragma once), which also ends cycles.
  for (const auto& seen : included)
    if (seen == name) return;
  included.push_back(name);
  std::string text = read_shader_text(path, display);
  int file_index = static_cast<int>(out.files.size());
  out.files.push_back(display);
  out.paths.push_back(path);

  static const std::regex include_re(R"(^\s*#\s*include\s*\"([^\"]*)\"\s*(//.*)?$)");
  static const std::regex version_re(R"(^\s*#\s*version\b.*)");
  std::istringstream lines(text);
  std::string line;
  int number = 0;
  bool seen_code = false;
  while (std::getline(lines, line)) {
    ++number;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    std::smatch m;
    if (std::regex_match(line, version_re)) {
      if (!top_level)
        throw Error(display + ":" + std::to_string(number) + ": an included file must not declare #version");
      if (seen_code || trim(line) != kRequiredVersionLine)
        throw Error(display + ":" + std::to_string(number) + ": the first line must be \"" +
                    kRequiredVersionLine + "\" (found \"" + trim(line) + "\")");
    } else if ((seen_code || !top_level) && std::regex_match(line, m, include_re)) {
      // An include ahead of a top-level #version is left to the first-line check
      // below, which refuses it: its text would come before the version line.
      try {
        append(m[1].str(), out, included, depth + 1, false);
      } catch (const Error& e) {
        throw Error(display + ":" + std::to_string(number) + ": in #include \"" + m[1].str() + "\": " + e.what());
      }
      continue;
    } else if (top_level && !seen_code && !trim(line).empty()) {
      throw Error(display + ":" + std::to_string(number) + ": the first line must be \"" +
                  kRequiredVersionLine + "\"");
    }
    if (!trim(line).empty()) seen_code = true;
    out.text += line;
    out.text += '\n';
    out.lines.push_back({file_index, number});
  }
}

std::string AssembledShader::map_log(const std::string& log) const {
  // Mesa: "0:12(3): error: ..."; NVIDIA: "0(12) : error ...".
  static const std::regex mesa_re(R"((\d+):(\d+)\((\d+)\))");
  static const std::regex nvidia_re(R"(^(\d+)\((\d+)\))");
  std::istringstream in(log);
  std::string line, result;
  auto where = [&](int assembled_line) -> std::string {
    if (assembled_line >= 1 && assembled_line <= static_cast<int>(lines.size())) {
      const SourceLine& s = lines[assembled_line - 1];
      return files[s.file] + ":" + std::to_string(s.line);
    }
    return files.empty() ? std::string("?") : files[0] + ":?";
  };
  while (std::getline(in, line)) {
    std::smatch m;
    if (std::regex_search(line, m, mesa_re) && m.position(0) == 0) {
      line = where(std::stoi(m[2].str())) + ":" + m[3].str() + line.substr(m.length(0));
    } else if (std::regex_search(line, m, nvidia_re)) {
      line = where(std::stoi(m[2].str())) + line.substr(m.length(0));
    }
    result += line + "\n";
  }
  return result;
}

}  // namespace kit
