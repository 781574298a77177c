#include "render/interface_check.h"

#include <algorithm>
#include <cctype>
#include <set>
#include <vector>

#include "base/error.h"

namespace kit {

namespace {

struct Varying {
  std::string type, name;
  size_t offset = 0;  // of its declaration in the code
};

// Qualifiers that may stand between `layout(...)` and the type of a declaration.
bool is_qualifier(const std::string& word) {
  static const std::set<std::string> kQualifiers = {"flat",      "smooth", "noperspective", "centroid", "invariant",
                                                    "sample",    "highp",  "mediump",       "lowp"};
  return kQualifiers.count(word) > 0;
}

bool identifier_char(char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; }

// Comments and preprocessor lines blanked out (the assembled text has its
// includes inlined); every newline is kept, so offsets still tell the line.
std::string code_only(const std::string& text) {
  std::string out;
  bool line_start = true;
  for (size_t i = 0; i < text.size(); ++i) {
    if (text.compare(i, 2, "//") == 0) {
      while (i < text.size() && text[i] != '\n') ++i;
    } else if (text.compare(i, 2, "/*") == 0) {
      size_t end = text.find("*/", i + 2);
      end = end == std::string::npos ? text.size() : end + 2;
      out += ' ';
      for (; i < end; ++i)
        if (text[i] == '\n') out += '\n';
      --i;
      continue;
    } else if (line_start && text[i] == '#') {
      while (i < text.size() && text[i] != '\n') ++i;
    }
    if (i >= text.size()) break;
    out += text[i];
    if (text[i] == '\n') line_start = true;
    else if (!std::isspace(static_cast<unsigned char>(text[i]))) line_start = false;
  }
  return out;
}

struct Statement {
  std::string text;   // a statement that had a block ({...}) starts with '{'
  size_t offset = 0;  // where its first character is in the code
};

// Statements at global scope, with function bodies and blocks left out. One
// pass, no rescans of the statement so far: a file of newlines or of '}' (up to
// 256 KiB) stays linear.
std::vector<Statement> global_statements(const std::string& code) {
  std::vector<Statement> out;
  Statement current;
  bool has_text = false, has_paren = false;  // of `current`: a non-space character, a '('
  int depth = 0;
  bool had_block = false;
  auto next = [&] {
    current = Statement();
    has_text = has_paren = had_block = false;
  };
  for (size_t i = 0; i < code.size(); ++i) {
    char c = code[i];
    if (c == '{') {
      if (depth++ == 0) had_block = true;
      continue;
    }
    if (c == '}') {
      depth = std::max(0, depth - 1);
      if (depth == 0 && has_paren) next();  // a function body ended
      continue;
    }
    if (depth > 0) continue;
    if (c == ';') {
      if (had_block) current.text.insert(0, "{");
      out.push_back(current);
      next();
      continue;
    }
    if (!has_text && !std::isspace(static_cast<unsigned char>(c))) {
      current.offset = i;
      has_text = true;
    }
    has_paren = has_paren || c == '(';
    current.text += c;
  }
  return out;
}

std::vector<std::string> words(const std::string& text) {
  std::vector<std::string> out;
  std::string w;
  for (char c : text) {
    if (identifier_char(c) || c == '[' || c == ']' || c == ',' || c == '=') {
      w += c;
    } else if (!w.empty()) {
      out.push_back(w);
      w.clear();
    }
  }
  if (!w.empty()) out.push_back(w);
  return out;
}

// Global declarations with storage qualifier `storage` ("in" or "out"): `out vec3 a, b[2];`.
std::vector<Varying> declarations(const std::string& code, const std::string& storage) {
  std::vector<Varying> out;
  for (const Statement& s : global_statements(code)) {
    std::string statement = s.text;
    if (!statement.empty() && statement[0] == '{') continue;  // interface blocks: matched by block name, not checked
    size_t layout = statement.find("layout");
    if (layout != std::string::npos) {
      size_t close = statement.find(')', layout);
      if (close == std::string::npos) continue;
      statement.erase(layout, close - layout + 1);
    }
    std::vector<std::string> w = words(statement);
    size_t i = 0;
    while (i < w.size() && is_qualifier(w[i])) ++i;
    if (i + 2 > w.size() || w[i] != storage) continue;
    std::string type = w[i + 1];
    std::string rest;
    for (size_t k = i + 2; k < w.size(); ++k) rest += w[k];
    size_t start = 0;
    while (start <= rest.size()) {
      size_t comma = rest.find(',', start);
      std::string declarator = rest.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
      size_t end = 0;
      while (end < declarator.size() && identifier_char(declarator[end])) ++end;
      std::string suffix = declarator.substr(end);  // an array size belongs to the type
      suffix = suffix.substr(0, suffix.find('='));
      if (end > 0) out.push_back({type + suffix, declarator.substr(0, end), s.offset});
      if (comma == std::string::npos) break;
      start = comma + 1;
    }
  }
  return out;
}

// "file:line" of an offset into code_only(shader.text).
std::string where(const AssembledShader& shader, const std::string& code, size_t offset) {
  size_t line = static_cast<size_t>(std::count(code.begin(), code.begin() + static_cast<std::ptrdiff_t>(std::min(offset, code.size())), '\n'));
  if (line >= shader.lines.size()) return shader.files.front();
  const SourceLine& s = shader.lines[line];
  return shader.files[static_cast<size_t>(s.file)] + ":" + std::to_string(s.line);
}

// "Statically read", approximated: the name occurs again after its declaration.
bool used(const std::string& code, const std::string& name) {
  int count = 0;
  for (size_t at = code.find(name); at != std::string::npos; at = code.find(name, at + name.size())) {
    bool starts = at == 0 || !identifier_char(code[at - 1]);
    bool ends = at + name.size() >= code.size() || !identifier_char(code[at + name.size()]);
    if (starts && ends && ++count >= 2) return true;
  }
  return false;
}

void check_pair(const ShaderLibrary& library, const std::string& vertex, const std::string& fragment) {
  AssembledShader vs = library.assemble(vertex), fs = library.assemble(fragment);
  std::string vs_code = code_only(vs.text), fs_code = code_only(fs.text);
  std::vector<Varying> outputs = declarations(vs_code, "out");
  std::string written;
  for (const Varying& o : outputs) written += (written.empty() ? "" : ", ") + o.name;
  std::string problems;
  for (const Varying& in : declarations(fs_code, "in")) {
    if (!used(fs_code, in.name)) continue;
    auto match = std::find_if(outputs.begin(), outputs.end(), [&](const Varying& o) { return o.name == in.name; });
    std::string line = "\n" + where(fs, fs_code, in.offset) + ": fragment shader input `" + in.name + "' ";
    if (match == outputs.end())
      problems += line + "has no matching output in the vertex shader " + vs.files.front() + " (it writes: " +
                  (written.empty() ? "nothing" : written) + ")";
    else if (match->type != in.type)
      problems += line + "is " + in.type + ", the vertex shader's output (" + where(vs, vs_code, match->offset) +
                  ") " + match->type;
  }
  if (!problems.empty())
    throw Error("link error (" + vs.files.front() + " + " + fs.files.front() + "):" + problems +
                "\nMesa would read zeros for such an input; other OpenGL drivers refuse to link the program.");
}

}  // namespace

void check_stage_interfaces(const Stage& stage, const ShaderLibrary& library) {
  auto has = [&](const std::string& f) { return std::find(stage.files.begin(), stage.files.end(), f) != stage.files.end(); };
  // A fragment shader pairs with the vertex shader of its own name where the stage has
  // one (gbuffer, light_volume), else with the full-screen pass's.
  for (const std::string& file : stage.files) {
    const bool fragment = file.size() > 5 && file.compare(file.size() - 5, 5, ".frag") == 0;
    if (!fragment) continue;
    const std::string vertex = file.substr(0, file.size() - 5) + ".vert";
    const bool own = has(vertex) || file == "gbuffer.frag";  // lab 1's pair, also where only one of them is the lab's
    check_pair(library, own ? vertex : "fullscreen.vert", file);
  }
  if (has("gbuffer.vert") && !has("gbuffer.frag")) check_pair(library, "gbuffer.vert", "gbuffer.frag");
}

}  // namespace kit
