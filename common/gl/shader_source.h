#pragma once
// Shader text assembly with a tiny, confined #include resolver.
//
// A shader is looked up by plain file name in an ordered list of folders (the
// stage's lab folder first, then earlier steps' solutions, then shaders/). An
// `#include "name"` line is resolved the same way. Names may not hold '/', '\'
// or "..", and a file whose real path (symlinks followed) leaves its folder is
// refused, so a submission can never make the kit read anything but shader text
// from inside the allowed folders.
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <map>
#include <string>
#include <utility>
#include <vector>

namespace kit {

struct ShaderFolder {
  std::filesystem::path path;
  std::string label;  // how file names are shown in messages, e.g. "labs/02-lighting"
  // When not empty, only these names are looked up here (a lab folder supplies
  // its own step's files and nothing else, so stages stay graded in isolation).
  std::vector<std::string> only;
};

// Where each line of the assembled text came from, for mapping compiler logs.
struct SourceLine {
  int file = 0;  // index into AssembledShader::files
  int line = 0;  // 1-based line in that file
};

struct AssembledShader {
  std::string text;
  std::vector<SourceLine> lines;               // one per line of `text`
  std::vector<std::string> files;              // display names ("labs/02-lighting/brdf.glsl")
  std::vector<std::filesystem::path> paths;    // real paths, for hot reload
  // Rewrites "0:12(3): error" (Mesa), "0(12) : error" (NVIDIA) and "ERROR: 0:12: ..." (ANGLE,
  // WebGL's compiler) into "file:line[:col]: error ...".
  std::string map_log(const std::string& log) const;
  // "FILE:LINE" of the 0-based line `index` of `text`, as messages name it.
  std::string where(size_t index) const;
};

// Files larger than this are refused before they are read (a shader is text).
constexpr std::uintmax_t kMaxShaderFileBytes = 256 * 1024;
// Longest line accepted, in bytes (its line break not counted): the kit's own
// shaders stay under 130; a longer line is refused naming its file and line.
constexpr std::size_t kMaxShaderLineBytes = 4096;
// Most tokens one line of an assembled shader may become once its macros are expanded. A
// macro that uses another twice doubles it: 30 such #defines are a billion tokens, which
// no GLSL compiler survives (Mesa runs out of memory, a browser's tab stops answering), so
// such a shader is refused by file and line before it reaches GL, on the desktop and in
// the browser alike. The kit's own shaders stay under 200 tokens a line expanded.
constexpr std::uint64_t kMaxExpandedLineTokens = 1u << 16;
// And the whole shader: a 60,000-token macro on every one of a thousand lines is as bad.
constexpr std::uint64_t kMaxExpandedShaderTokens = 1u << 20;
// Every top-level shader must start with this line: the kit targets GL 3.3 core.
constexpr const char* kRequiredVersionLine = "#version 330 core";

// Which GLSL a library's shaders are compiled as. Lab shaders are written as GLSL 3.30
// core on every target; for WebGL2 the assembled text becomes GLSL ES 3.00
// (translate_to_glsl_es), so the same files compile in the browser.
enum class ShaderTarget { Glsl330Core, GlslEs300 };
// The target of the GL this build draws with: GLSL ES 3.00 in the browser build
// (emscripten, WebGL2), GLSL 3.30 core elsewhere.
#if defined(__EMSCRIPTEN__)
constexpr ShaderTarget kBuildShaderTarget = ShaderTarget::GlslEs300;
#else
constexpr ShaderTarget kBuildShaderTarget = ShaderTarget::Glsl330Core;
#endif

// The #version line and precision statements a GLSL ES 3.00 shader starts with:
// highp everywhere, as desktop GLSL computes, and a precision for every sampler type
// GLSL ES 3.00 gives none by default.
constexpr const char* kGlslEsVersionLine = "#version 300 es";
constexpr const char* kGlslEsPrecisions =
    "precision highp float; precision highp int; precision highp sampler2D; precision highp sampler3D; "
    "precision highp samplerCube; precision highp sampler2DShadow; precision highp samplerCubeShadow; "
    "precision highp sampler2DArray; precision highp sampler2DArrayShadow; precision highp isampler2D; "
    "precision highp isampler3D; precision highp isamplerCube; precision highp isampler2DArray; "
    "precision highp usampler2D; precision highp usampler3D; precision highp usamplerCube; "
    "precision highp usampler2DArray;";

// Turns an assembled GLSL 3.30 core shader (its first line kRequiredVersionLine) into
// GLSL ES 3.00 in place: the version line becomes kGlslEsVersionLine, followed by one
// line of kGlslEsPrecisions that `lines` maps to the version line, so every other line
// still maps to its file and line. Throws kit::Error "FILE:LINE: ..." naming the
// construct at the first use of one GLSL ES 3.00 lacks (1D, rectangle and buffer
// samplers, double precision, gl_ClipDistance, noperspective, ...); comments are not
// looked at.
void translate_to_glsl_es(AssembledShader& shader);

class LinkedProgramCache;  // gl_objects.h

// Assembled shaders kept by their files' folders, name and defines, for libraries whose
// files cannot change while the cache lives (a grading child's private copy of a
// submission): each scene's Renderer assembles the same shaders again, and reading and
// parsing their files each time was 2 % of a grading run's CPU. Not for the viewer, whose
// hot reload reads a file again when it changes.
class AssembledShaderCache {
 public:
  const AssembledShader* find(const std::string& key) const;
  void store(const std::string& key, const AssembledShader& shader) { shaders_[key] = shader; }

 private:
  std::map<std::string, AssembledShader> shaders_;
};

class ShaderLibrary {
 public:
  ShaderLibrary() = default;
  explicit ShaderLibrary(std::vector<ShaderFolder> folders);

  const std::vector<ShaderFolder>& folders() const { return folders_; }
  // The first folder holding `name`, as a validated real path; throws kit::Error.
  std::filesystem::path locate(const std::string& name, std::string* display = nullptr) const;
  // Reads a top-level shader and everything it includes; throws kit::Error.
  AssembledShader assemble(const std::string& name) const;
  // The framework's own switches: `#define NAME` right after the #version line of every
  // shader assembled while it is set that names it somewhere (errors still name the
  // student's files and lines). A shader that never names NAME cannot depend on it, so its
  // text, and the program built from it, stay the same when NAME changes.
  void set_define(const std::string& name, bool on);
  bool has_define(const std::string& name) const;
  const std::vector<std::string>& defines() const { return defines_; }  // sorted
  // set_define for each (name, on).
  void set_defines(const std::vector<std::pair<std::string, bool>>& defines);
  // Where programs built from this library (Program) look for a linked program made from
  // the same texts before compiling one; null (the default) compiles each.
  void share_programs_through(LinkedProgramCache* cache) { program_cache_ = cache; }
  LinkedProgramCache* program_cache() const { return program_cache_; }
  // Where assemble() looks first and keeps what it assembles; null (the default) reads the
  // files each time. Only for files that cannot change while `cache` lives.
  void keep_assembled_in(AssembledShaderCache* cache) { assembled_cache_ = cache; }
  // Which GLSL assemble() produces; kBuildShaderTarget unless set.
  void set_target(ShaderTarget target) { target_ = target; }
  ShaderTarget target() const { return target_; }

 private:
  void append(const std::string& name, AssembledShader& out, std::vector<std::string>& included,
              int depth, bool top_level) const;
  std::vector<ShaderFolder> folders_;
  // Each folder's real path, resolved once: a shader assembles from up to a dozen files, and
  // resolving every one's folder and name again was 30k system calls a grading run.
  std::vector<std::filesystem::path> real_folders_;
  std::string folders_key_;  // the folders as AssembledShaderCache's keys begin
  std::vector<std::string> defines_;
  LinkedProgramCache* program_cache_ = nullptr;
  AssembledShaderCache* assembled_cache_ = nullptr;
  ShaderTarget target_ = kBuildShaderTarget;
};

// One token of a line of shader text, [begin, end) in the line: identifiers and numbers
// whole, any other character one token, comments left out.
struct ShaderToken {
  size_t begin = 0, end = 0;
  bool word = false;  // an identifier or number
};
// The tokens of `line`; `in_comment` (inside a /* */ an earlier line opened) is carried on.
// Scanned by hand, never with std::regex (its matcher recurses once per character).
std::vector<ShaderToken> shader_line_tokens(const std::string& line, bool& in_comment);

// Throws kit::Error "FILE:LINE: ..." at the first line of `shader` whose macros expand to more
// than kMaxExpandedLineTokens tokens, naming the macro, or where the shader's expanded tokens
// pass kMaxExpandedShaderTokens. An upper bound: a macro's size is
// its body's tokens with each macro it names counted at that macro's size (a function-like
// macro's parameters as one token each), whatever #if would skip. assemble() calls it.
void check_macro_expansion(const AssembledShader& shader, std::uint64_t line_limit = kMaxExpandedLineTokens,
                           std::uint64_t shader_limit = kMaxExpandedShaderTokens);

// Reads a whole file as shader text: size limit, no NUL bytes, valid UTF-8,
// not empty, no line longer than kMaxShaderLineBytes. A UTF-8 byte-order mark at the start is dropped. Throws kit::Error
// naming `display`.
std::string read_shader_text(const std::filesystem::path& path, const std::string& display);

// Whether `line` declares the uniform `name`: the word "uniform", then further on with
// no ';' between them the word `name` (what the regex \buniform\b[^;]*\bNAME\b found,
// scanned by hand like the shader assembler's lines; words are [A-Za-z0-9_] runs).
bool declares_uniform(const std::string& line, const std::string& name);

// True when `name` is a plain file name the resolver accepts.
bool is_plain_shader_name(const std::string& name);

}  // namespace kit
