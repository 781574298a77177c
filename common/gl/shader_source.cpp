#include "gl/shader_source.h"

#include <algorithm>
#include <climits>
#include <fstream>
#include <map>
#include <sstream>

#include "base/error.h"
#include "gl/loop_guard.h"

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

// Lines are scanned by hand, never with std::regex: libstdc++'s regex matcher
// recurses once per character, so one long line (a file is up to 256 KiB) would
// overflow the stack. Whitespace is what \s matched: space, \t, \n, \v, \f, \r.
bool is_space(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\v' || c == '\f' || c == '\r'; }
bool is_word(char c) {
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_';
}
size_t skip_space(const std::string& s, size_t i) {
  while (i < s.size() && is_space(s[i])) ++i;
  return i;
}

// Where the directive's name starts when `line` is "<space>#<space>NAME...", else npos.
size_t directive_name(const std::string& line) {
  size_t i = skip_space(line, 0);
  if (i >= line.size() || line[i] != '#') return std::string::npos;
  return skip_space(line, i + 1);
}

// "#version" followed by the end of the line or a character that ends the word.
bool is_version_line(const std::string& line) {
  size_t i = directive_name(line);
  if (i == std::string::npos || line.compare(i, 7, "version") != 0) return false;
  return i + 7 == line.size() || !is_word(line[i + 7]);
}

// `#include "name"`, optionally followed by a // comment; sets *name.
bool is_include_line(const std::string& line, std::string* name) {
  size_t i = directive_name(line);
  if (i == std::string::npos || line.compare(i, 7, "include") != 0) return false;
  i = skip_space(line, i + 7);
  if (i >= line.size() || line[i] != '"') return false;
  size_t close = line.find('"', i + 1);
  if (close == std::string::npos) return false;
  size_t rest = skip_space(line, close + 1);
  if (rest < line.size() && (line.compare(rest, 2, "//") != 0 || line.find('\r', rest) != std::string::npos))
    return false;
  *name = line.substr(i + 1, close - i - 1);
  return true;
}

// The run of decimal digits at `*i` as an int (INT_MAX when it does not fit);
// false when there is none. Advances *i past it.
bool read_number(const std::string& s, size_t* i, int* value) {
  size_t start = *i;
  long long v = 0;
  for (; *i < s.size() && s[*i] >= '0' && s[*i] <= '9'; ++*i) v = std::min<long long>(v * 10 + (s[*i] - '0'), INT_MAX);
  *value = static_cast<int>(v);
  return *i > start;
}

// The "0:12(3)" (Mesa) or "0(12)" (NVIDIA) that starts a compiler log line: the
// assembled line's number, the column's digits (Mesa only, else "") and where it ends.
bool log_location(const std::string& line, int* number, std::string* column, size_t* end) {
  size_t i = 0;
  int source = 0, ignored = 0;
  if (!read_number(line, &i, &source) || i >= line.size()) return false;
  if (line[i] == ':') {
    size_t open = i + 1;
    if (!read_number(line, &open, number) || open >= line.size() || line[open] != '(') return false;
    size_t close = open + 1;
    if (!read_number(line, &close, &ignored) || close >= line.size() || line[close] != ')') return false;
    *column = line.substr(open + 1, close - open - 1);
    *end = close + 1;
    return true;
  }
  if (line[i] != '(') return false;
  size_t close = i + 1;
  if (!read_number(line, &close, number) || close >= line.size() || line[close] != ')') return false;
  column->clear();
  *end = close + 1;
  return true;
}

// The "ERROR: 0:12:" (or "WARNING: 0:12:") that starts a log line of ANGLE, the GLSL
// compiler of Chromium's and Firefox's WebGL: its severity in lower case, the assembled
// line's number and where the location ends (after the colon).
bool angle_location(const std::string& line, std::string* severity, int* number, size_t* end) {
  size_t i = 0;
  if (line.compare(0, 7, "ERROR: ") == 0) *severity = "error", i = 7;
  else if (line.compare(0, 9, "WARNING: ") == 0) *severity = "warning", i = 9;
  else return false;
  int source = 0;
  if (!read_number(line, &i, &source) || i >= line.size() || line[i] != ':') return false;
  ++i;
  if (!read_number(line, &i, number) || i >= line.size() || line[i] != ':') return false;
  *end = i + 1;
  return true;
}

// Whether a word starts or ends at `i` in `s` (regex's \b): a word character on one side only.
bool word_boundary(const std::string& s, size_t i) {
  return (i > 0 && is_word(s[i - 1])) != (i < s.size() && is_word(s[i]));
}

// Whether `word` stands at `i` in `s` with a word boundary on both sides (\bWORD\b).
bool whole_word_at(const std::string& s, size_t i, const std::string& word) {
  return s.compare(i, word.size(), word) == 0 && word_boundary(s, i) && word_boundary(s, i + word.size());
}

// Whether `word` stands anywhere in `text` as a whole word.
bool names_word(const std::string& text, const std::string& word) {
  for (size_t i = text.find(word); i != std::string::npos; i = text.find(word, i + 1))
    if (whole_word_at(text, i, word)) return true;
  return false;
}

}  // namespace

bool declares_uniform(const std::string& line, const std::string& name) {
  static const std::string kUniform = "uniform";
  for (size_t u = line.find(kUniform); u != std::string::npos; u = line.find(kUniform, u + 1)) {
    if (!whole_word_at(line, u, kUniform)) continue;
    const size_t from = u + kUniform.size(), to = std::min(line.find(';', from), line.size());
    for (size_t j = from; j <= to; ++j)
      if (whole_word_at(line, j, name)) return true;
  }
  return false;
}

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
  size_t number = 1;
  for (size_t start = 0; start < text.size(); ++number) {
    size_t end = std::min(text.find('\n', start), text.size());
    size_t length = end - start - (end > start && text[end - 1] == '\r' ? 1 : 0);
    if (length > kMaxShaderLineBytes)
      throw Error(display + ":" + std::to_string(number) + ": line is " + std::to_string(length) +
                  " bytes long, over the " + std::to_string(kMaxShaderLineBytes) +
                  "-byte limit for a line of shader text (kit::kMaxShaderLineBytes)");
    start = end + 1;
  }
  return text;
}

ShaderLibrary::ShaderLibrary(std::vector<ShaderFolder> folders) : folders_(std::move(folders)) {
  for (const ShaderFolder& folder : folders_) {
    std::error_code ec;
    fs::path real = fs::weakly_canonical(folder.path, ec);
    real_folders_.push_back(ec ? fs::path() : real);  // empty: locate says it cannot resolve it
    folders_key_ += folder.path.string() + '\n' + folder.label + '\n';
    for (const std::string& only : folder.only) folders_key_ += only + ' ';
    folders_key_ += '\n';
  }
}

fs::path ShaderLibrary::locate(const std::string& name, std::string* display) const {
  if (!is_plain_shader_name(name))
    throw Error("shader name \"" + name + "\" is refused: only plain file names inside the kit's "
                "shader folders can be loaded or included (no '/', '\\' or '..')");
  for (size_t i = 0; i < folders_.size(); ++i) {
    const ShaderFolder& folder = folders_[i];
    if (!folder.only.empty() && std::find(folder.only.begin(), folder.only.end(), name) == folder.only.end()) continue;
    fs::path candidate = folder.path / name;
    std::error_code ec;
    const fs::file_status status = fs::symlink_status(candidate, ec);
    if (!fs::exists(status)) continue;
    std::string shown = folder.label + "/" + name;
    const fs::path& root = real_folders_[i];
    if (root.empty()) throw Error(shown + ": its folder's real path cannot be resolved (" + folder.path.string() + ")");
    // A plain name (no separator, no "..") that is not a link names a file in the folder itself.
    fs::path real = root / name;
    fs::file_status target = status;
    if (fs::is_symlink(status)) {
      real = fs::weakly_canonical(candidate, ec);
      if (ec || !is_inside(real, root))
        throw Error(shown + ": refused, it links outside its folder (" + real.string() + ")");
      target = fs::status(real, ec);
    }
    if (!fs::is_regular_file(target)) throw Error(shown + ": not a regular file");
    if (display) *display = shown;
    return real;
  }
  std::string where;
  for (const auto& f : folders_) where += (where.empty() ? "" : ", ") + f.label;
  throw Error("shader file \"" + name + "\" not found in " + (where.empty() ? "(no folders)" : where));
}

const AssembledShader* AssembledShaderCache::find(const std::string& key) const {
  auto it = shaders_.find(key);
  return it == shaders_.end() ? nullptr : &it->second;
}

AssembledShader ShaderLibrary::assemble(const std::string& name) const {
  std::string key;
  if (assembled_cache_) {
    // Everything the text depends on but the files' contents: where each name is looked up,
    // the name, the defines.
    key = folders_key_ + name + '\n';
    for (const std::string& define : defines_) key += define + ' ';
    if (target_ == ShaderTarget::GlslEs300) key += "\nes";
    if (const AssembledShader* kept = assembled_cache_->find(key)) return *kept;
  }
  AssembledShader out;
  std::vector<std::string> included;
  append(name, out, included, 0, true);
  // After the version line (the first line: append() refuses anything else there),
  // counted as that line for error messages.
  const size_t after_version = out.text.find('\n') + 1;
  for (const std::string& define : defines_) {
    if (!names_word(out.text, define)) continue;
    out.text.insert(after_version, "#define " + define + "\n");
    out.lines.insert(out.lines.begin() + 1, out.lines.front());
  }
  check_macro_expansion(out);
  if (target_ == ShaderTarget::GlslEs300) {
    translate_to_glsl_es(out);
    guard_loops(out);
  }
  if (assembled_cache_) assembled_cache_->store(key, out);
  return out;
}

void ShaderLibrary::set_define(const std::string& name, bool on) {
  // Kept sorted: the same set of defines always assembles to the same text.
  auto it = std::lower_bound(defines_.begin(), defines_.end(), name);
  const bool present = it != defines_.end() && *it == name;
  if (on && !present) defines_.insert(it, name);
  if (!on && present) defines_.erase(it);
}

bool ShaderLibrary::has_define(const std::string& name) const {
  return std::binary_search(defines_.begin(), defines_.end(), name);
}

void ShaderLibrary::set_defines(const std::vector<std::pair<std::string, bool>>& defines) {
  for (const auto& [name, on] : defines) set_define(name, on);
}

void ShaderLibrary::append(const std::string& name, AssembledShader& out,
                           std::vector<std::string>& included, int depth, bool top_level) const {
  if (depth > kMaxIncludeDepth) throw Error("#include nesting deeper than " + std::to_string(kMaxIncludeDepth) + " at \"" + name + "\"");
  // Every file is included once per shader (like #pragma once), which also ends cycles.
  for (const auto& seen : included)
    if (seen == name) return;
  std::string display;
  fs::path path = locate(name, &display);
  included.push_back(name);
  std::string text = read_shader_text(path, display);
  int file_index = static_cast<int>(out.files.size());
  out.files.push_back(display);
  out.paths.push_back(path);

  std::istringstream lines(text);
  std::string line;
  int number = 0;
  bool seen_code = false;
  while (std::getline(lines, line)) {
    ++number;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    std::string included_name;
    if (is_version_line(line)) {
      if (!top_level)
        throw Error(display + ":" + std::to_string(number) + ": an included file must not declare #version");
      if (seen_code || trim(line) != kRequiredVersionLine)
        throw Error(display + ":" + std::to_string(number) + ": the first line must be \"" +
                    kRequiredVersionLine + "\" (found \"" + trim(line) + "\")");
    } else if ((seen_code || !top_level) && is_include_line(line, &included_name)) {
      // An include ahead of a top-level #version is left to the first-line check
      // below, which refuses it: its text would come before the version line.
      try {
        append(included_name, out, included, depth + 1, false);
      } catch (const Error& e) {
        throw Error(display + ":" + std::to_string(number) + ": in #include \"" + included_name + "\": " + e.what());
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

std::vector<ShaderToken> shader_line_tokens(const std::string& line, bool& in_comment) {
  std::vector<ShaderToken> out;
  size_t i = 0;
  while (i < line.size()) {
    if (in_comment) {
      const size_t end = line.find("*/", i);
      if (end == std::string::npos) break;
      in_comment = false;
      i = end + 2;
    } else if (line.compare(i, 2, "//") == 0) {
      break;
    } else if (line.compare(i, 2, "/*") == 0) {
      in_comment = true;
      i += 2;
    } else if (is_space(line[i])) {
      ++i;
    } else if (is_word(line[i])) {
      size_t j = i;
      while (j < line.size() && is_word(line[j])) ++j;
      out.push_back({i, j, true});
      i = j;
    } else {
      out.push_back({i, i + 1, false});
      ++i;
    }
  }
  return out;
}

void check_macro_expansion(const AssembledShader& shader, std::uint64_t line_limit, std::uint64_t shader_limit) {
  const std::uint64_t limit = line_limit;
  std::map<std::string, std::uint64_t> size;  // each defined macro's expanded size, capped at limit + 1
  const auto expanded = [&](const std::vector<std::string>& tokens, size_t from, const std::string& self,
                            std::string* largest) {
    std::uint64_t total = 0, most = 0;
    for (size_t t = from; t < tokens.size(); ++t) {
      auto it = tokens[t] == self ? size.end() : size.find(tokens[t]);
      const std::uint64_t n = it == size.end() ? 1 : it->second;
      if (largest && n > most) {
        most = n;
        *largest = tokens[t];
      }
      total = std::min(total + n, limit + 1);
    }
    return total;
  };
  std::istringstream text(shader.text);
  std::string line;
  bool in_comment = false;
  std::uint64_t whole = 0;
  for (size_t index = 0; std::getline(text, line); ++index) {
    std::vector<std::string> tokens;
    for (const ShaderToken& t : shader_line_tokens(line, in_comment)) tokens.push_back(line.substr(t.begin, t.end - t.begin));
    const bool directive = !tokens.empty() && tokens[0] == "#";
    if (directive && tokens.size() >= 3 && tokens[1] == "define") {
      // The body after the name and, for a function-like macro, its parameter list.
      size_t body = 3;
      if (tokens.size() > 3 && tokens[3] == "(" && line.find(tokens[2] + "(") != std::string::npos)
        while (body < tokens.size() && tokens[body++] != ")") {
        }
      size[tokens[2]] = expanded(tokens, body, tokens[2], nullptr);
      continue;
    }
    if (directive && tokens.size() >= 3 && tokens[1] == "undef") {
      size.erase(tokens[2]);
      continue;
    }
    // #if and #elif expand their macros too; #include and #version name none.
    std::string macro;
    const std::uint64_t n = expanded(tokens, directive ? 2 : 0, "", &macro);
    whole += n;
    if (n > limit || whole > shader_limit) {
      const std::string what =
          n > limit ? macro + " expands to more than " + std::to_string(limit) + " tokens on this line"
                    : "the shader's macros expand to more than " + std::to_string(shader_limit) +
                          " tokens by this line (" + macro + " the largest here)";
      throw Error(shader.where(std::min(index, shader.lines.size() - 1)) + ": " + what +
                  " (a macro that names another twice doubles it): the kit refuses it before compiling, as a GLSL "
                  "compiler would run out of memory or time on it");
    }
  }
}

namespace {

// What GLSL 3.30 core has and GLSL ES 3.00 lacks, as whole words, with what to write
// instead. Found by word, outside comments: a construct spelled inside a #define is
// found there too.
struct MissingConstruct {
  const char* word;
  const char* instead;
};
const MissingConstruct kMissingInEs[] = {
    {"sampler1D", "use a sampler2D one texel high"},
    {"sampler1DShadow", "use a sampler2DShadow"},
    {"sampler1DArray", "use a sampler2DArray"},
    {"sampler1DArrayShadow", "use a sampler2DArrayShadow"},
    {"isampler1D", "use an isampler2D"},
    {"usampler1D", "use a usampler2D"},
    {"isampler1DArray", "use an isampler2DArray"},
    {"usampler1DArray", "use a usampler2DArray"},
    {"sampler2DRect", "use a sampler2D and texelFetch"},
    {"sampler2DRectShadow", "use a sampler2DShadow"},
    {"isampler2DRect", "use an isampler2D and texelFetch"},
    {"usampler2DRect", "use a usampler2D and texelFetch"},
    {"samplerBuffer", "use a sampler2D and texelFetch"},
    {"isamplerBuffer", "use an isampler2D and texelFetch"},
    {"usamplerBuffer", "use a usampler2D and texelFetch"},
    {"sampler2DMS", "the kit's targets are not multisampled"},
    {"isampler2DMS", "the kit's targets are not multisampled"},
    {"usampler2DMS", "the kit's targets are not multisampled"},
    {"sampler2DMSArray", "the kit's targets are not multisampled"},
    {"texture1D", "use texture() on a sampler2D"},
    {"texture1DLod", "use textureLod() on a sampler2D"},
    {"texture1DProj", "use textureProj() on a sampler2D"},
    {"texture2D", "use texture()"},
    {"texture2DLod", "use textureLod()"},
    {"texture2DProj", "use textureProj()"},
    {"texture3D", "use texture()"},
    {"textureCube", "use texture()"},
    {"shadow2D", "use texture() on a sampler2DShadow"},
    {"texelFetchOffset", "add the offset to texelFetch's coordinates"},
    {"double", "use float"},
    {"dvec2", "use vec2"},
    {"dvec3", "use vec3"},
    {"dvec4", "use vec4"},
    {"dmat2", "use mat2"},
    {"dmat3", "use mat3"},
    {"dmat4", "use mat4"},
    {"noperspective", "use smooth (the default)"},
    {"gl_ClipDistance", "clip in the fragment shader with discard"},
    {"gl_PrimitiveID", "pass what you need from the vertex shader"},
    {"gl_FragColor", "declare an out vec4 (layout(location = 0))"},
    {"gl_FragData", "declare out variables with layout(location = N)"},
    {"gl_Layer", "WebGL2 draws into one layer"},
};

// The first construct of kMissingInEs in `line` outside comments, or null; *in_comment
// carries a /* comment over to the next line.
const MissingConstruct* missing_in_es(const std::string& line, bool* in_comment) {
  for (size_t i = 0; i < line.size();) {
    if (*in_comment) {
      const size_t end = line.find("*/", i);
      if (end == std::string::npos) return nullptr;
      *in_comment = false;
      i = end + 2;
      continue;
    }
    if (line.compare(i, 2, "//") == 0) return nullptr;
    if (line.compare(i, 2, "/*") == 0) {
      *in_comment = true;
      i += 2;
      continue;
    }
    if (!is_word(line[i])) {
      ++i;
      continue;
    }
    size_t end = i;
    while (end < line.size() && is_word(line[end])) ++end;
    const std::string word = line.substr(i, end - i);
    for (const MissingConstruct& m : kMissingInEs)
      if (word == m.word) return &m;
    i = end;
  }
  return nullptr;
}

}  // namespace

void translate_to_glsl_es(AssembledShader& shader) {
  const size_t first_end = shader.text.find('\n');
  const std::string first = shader.text.substr(0, first_end);
  if (trim(first) != kRequiredVersionLine)
    throw Error(shader.where(0) + ": the first line must be \"" + std::string(kRequiredVersionLine) + "\" (found \"" +
                trim(first) + "\")");
  bool in_comment = false;
  size_t number = 0;
  for (size_t start = 0; start < shader.text.size(); ++number) {
    const size_t end = std::min(shader.text.find('\n', start), shader.text.size());
    if (number > 0) {
      if (const MissingConstruct* m = missing_in_es(shader.text.substr(start, end - start), &in_comment)) {
        throw Error(shader.where(number) + ": " + m->word + " is not in GLSL ES 3.00, which WebGL2 compiles (" + m->instead + ")");
      }
    }
    start = end + 1;
  }
  shader.text.replace(0, first_end == std::string::npos ? shader.text.size() : first_end,
                      std::string(kGlslEsVersionLine) + "\n" + kGlslEsPrecisions);
  if (!shader.lines.empty()) shader.lines.insert(shader.lines.begin() + 1, shader.lines.front());
}

std::string AssembledShader::where(size_t index) const {
  if (index < lines.size() && lines[index].file >= 0 && lines[index].file < static_cast<int>(files.size()))
    return files[lines[index].file] + ":" + std::to_string(lines[index].line);
  return "shader:" + std::to_string(index + 1);
}

std::string AssembledShader::map_log(const std::string& log) const {
  // Mesa: "0:12(3): error: ..."; NVIDIA: "0(12) : error ...". Both at the start of a line.
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
    int number = 0;
    std::string column;
    size_t end = 0;
    std::string severity;
    if (log_location(line, &number, &column, &end))
      line = where(number) + (column.empty() ? "" : ":" + column) + line.substr(end);
    else if (angle_location(line, &severity, &number, &end))
      line = where(number) + ": " + severity + ":" + line.substr(end);
    result += line + "\n";
  }
  return result;
}

}  // namespace kit
