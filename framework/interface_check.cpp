#include "interface_check.h"

#include <algorithm>
#include <cctype>
#include <set>
#include <vector>

#include "error.h"

namespace kit::grade {

namespace {

struct Varying {
  std::string type, name;
};

// Qualifiers that may stand between `layout(...)` and the type of a declaration.
bool is_qualifier(const std::string& word) {
  static const std::set<std::string> kQualifiers = {"flat",      "smooth", "noperspective", "centroid", "invariant",
                                                    "sample",    "highp",  "mediump",       "lowp"};
  return kQualifiers.count(word) > 0;
}

bool identifier_char(char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; }

// Comments and preprocessor lines removed (the assembled text has its includes inlined).
std::string code_only(const std::string& text) {
  std::string out;
  bool line_start = true;
  for (size_t i = 0; i < text.size(); ++i) {
    if (text.compare(i, 2, "//") == 0) {
      while (i < text.size() && text[i] != '\n') ++i;
    } else if (text.compare(i, 2, "/*") == 0) {
      size_t end = text.find("*/", i + 2);
      i = end == std::string::npos ? text.size() : end + 1;
      out += ' ';
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

// Statements at global scope, with function bodies and blocks left out; a
// statement that had a block ({...}) is marked by a leading '{'.
std::vector<std::string> global_statements(const std::string& code) {
  std::vector<std::string> out;
  std::string current;
  int depth = 0;
  bool had_block = false;
  for (char c : code) {
    if (c == '{') {
      if (depth++ == 0) had_block = true;
      continue;
    }
    if (c == '}') {
      depth = std::max(0, depth - 1);
      if (depth == 0 && current.find('(') != std::string::npos) {  // a function body ended
        current.clear();
        had_block = false;
      }
      continue;
    }
    if (depth > 0) continue;
    if (c == ';') {
      out.push_back((had_block ? "{" : "") + current);
      current.clear();
      had_block = false;
      continue;
    }
    current += c;
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
  for (std::string statement : global_statements(code)) {
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
      if (end > 0) out.push_back({type + suffix, declarator.substr(0, end)});
      if (comma == std::string::npos) break;
      start = comma + 1;
    }
  }
  return out;
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
    if (match == outputs.end())
      problems += "\nfragment shader input `" + in.name + "' has no matching output in the vertex shader (it writes: " +
                  (written.empty() ? "nothing" : written) + ")";
    else if (match->type != in.type)
      problems += "\nfragment shader input `" + in.name + "' is " + in.type + ", the vertex shader's output " + match->type;
  }
  if (!problems.empty())
    throw Error("link error (" + vs.files.front() + " + " + fs.files.front() + "):" + problems +
                "\nMesa would read zeros for such an input; other OpenGL drivers refuse to link the program.");
}

}  // namespace

void check_stage_interfaces(const Stage& stage, const ShaderLibrary& library) {
  auto has = [&](const std::string& f) { return std::find(stage.files.begin(), stage.files.end(), f) != stage.files.end(); };
  if (has("gbuffer.vert") || has("gbuffer.frag")) check_pair(library, "gbuffer.vert", "gbuffer.frag");
  for (const std::string& file : stage.files) {
    bool fragment = file.size() > 5 && file.compare(file.size() - 5, 5, ".frag") == 0;
    if (fragment && file != "gbuffer.frag") check_pair(library, "fullscreen.vert", file);
  }
}

}  // namespace kit::grade
