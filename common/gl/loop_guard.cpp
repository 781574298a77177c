#include "gl/loop_guard.h"

#include <algorithm>
#include <string>
#include <utility>
#include <vector>

#include "base/error.h"

namespace kit {

namespace {

// A token of the assembled text (shader_line_tokens's, placed in the whole text). `region`
// tells code (0) from each #directive's logical line (1, 2, ...): a loop's parentheses must
// close in the region its word is in.
struct Token {
  size_t begin = 0, end = 0;
  size_t line = 0;  // 0-based line of the assembled text
  int region = 0;
  bool word = false;
};

std::vector<Token> tokens_of(const std::string& text) {
  std::vector<Token> tokens;
  bool in_comment = false, continued = false, first = true;  // first: nothing yet on this logical line
  int region = 0, directives = 0;
  for (size_t start = 0, line = 0;; ++line) {
    const size_t end = std::min(text.find('\n', start), text.size());
    const std::string row = text.substr(start, end - start);
    if (!continued) {
      region = 0;
      first = true;
    }
    for (const ShaderToken& t : shader_line_tokens(row, in_comment)) {
      if (row[t.begin] == '\\') continue;  // a line continued
      if (first && row[t.begin] == '#') region = ++directives;
      first = false;
      tokens.push_back({start + t.begin, start + t.end, line, region, t.word});
    }
    // A backslash before the break continues a directive on the next line.
    continued = !row.empty() && row.back() == '\\';
    if (end == text.size()) break;
    start = end + 1;
  }
  return tokens;
}

}  // namespace

int loop_budget(int width, int height) {
  const std::int64_t pixels = std::max<std::int64_t>(std::int64_t{width} * height, 1);
  return static_cast<int>(std::max<std::int64_t>(kLoopIterationsPerInvocation, kLoopIterationsPerPass / pixels));
}

void guard_loops(AssembledShader& shader) {
  const std::string& text = shader.text;
  const std::vector<Token> tokens = tokens_of(text);
  auto word = [&](const Token& t) { return text.substr(t.begin, t.end - t.begin); };
  auto refuse = [&](const Token& t, const std::string& why) {
    throw Error(shader.where(t.line) + ": " + why +
                " (in the browser every loop is limited so that a loop that never ends cannot lock the page)");
  };
  // Next token of `region` after index k (tokens of other regions skipped: a directive
  // inside a loop's condition does not count); tokens.size() if none.
  auto next_in = [&](size_t k, int region) {
    for (++k; k < tokens.size(); ++k)
      if (tokens[k].region == region) return k;
    return tokens.size();
  };
  auto is = [&](size_t k, char c) {
    return k < tokens.size() && tokens[k].end == tokens[k].begin + 1 && text[tokens[k].begin] == c;
  };

  std::vector<std::pair<size_t, std::string>> inserts;  // (offset, text)
  for (size_t k = 0; k < tokens.size(); ++k) {
    const Token& t = tokens[k];
    const std::string w = word(t);
    if (w == "#" && t.end < text.size() && text[t.end] == '#')
      refuse(t, "token pasting (##) is not accepted in the browser, since it could spell a loop");
    if (w.rfind(kLoopGuardPrefix, 0) == 0)
      refuse(t, "the names starting with " + std::string(kLoopGuardPrefix) + " are the page's own");
    if (w != "while" && w != "for") continue;
    const size_t open = next_in(k, t.region);
    if (!is(open, '('))
      refuse(t, "`" + w + "' without its condition in parentheses right after it (a macro supplying them?)");
    size_t close = open, first_semicolon = 0, second_semicolon = 0;
    int depth = 0;
    for (size_t m = open; m < tokens.size(); m = next_in(m, t.region)) {
      if (is(m, '(')) ++depth;
      if (is(m, ')') && --depth == 0) {
        close = m;
        break;
      }
      if (depth == 1 && is(m, ';')) (first_semicolon ? second_semicolon : first_semicolon) = m;
    }
    if (close == open)
      refuse(t, "`" + w + "' whose parentheses do not close" +
                    (t.region ? std::string(" on its #define line") : std::string()));
    if (w == "for" && (!first_semicolon || !second_semicolon))
      refuse(t, "`for' without two semicolons in its parentheses");
    // A condition that declares a variable (`while (bool go = f())`: GLSL allows it) cannot
    // take the counter beside it; two words in a row begin only a declaration.
    const size_t condition = w == "while" ? next_in(open, t.region) : next_in(first_semicolon, t.region);
    const size_t after = next_in(condition, t.region);
    if (condition < close && after < close && tokens[condition].word && tokens[after].word)
      refuse(t, "`" + w + "' whose condition declares a variable (declare it before the loop)");
    if (w == "while") {
      inserts.emplace_back(tokens[open].end, "(");
      inserts.emplace_back(tokens[close].begin, ") && kit_loop_go_()");
      continue;
    }
    if (next_in(first_semicolon, t.region) == second_semicolon) {
      inserts.emplace_back(tokens[first_semicolon].end, " kit_loop_go_()");
    } else {
      inserts.emplace_back(tokens[first_semicolon].end, " (");
      inserts.emplace_back(tokens[second_semicolon].begin, ") && kit_loop_go_()");
    }
  }
  if (inserts.empty()) return;

  // The counter, on the precision line translate_to_glsl_es wrote (line 2).
  const size_t first_break = text.find('\n');
  const size_t second_break = first_break == std::string::npos ? std::string::npos : text.find('\n', first_break + 1);
  inserts.emplace_back(second_break == std::string::npos ? text.size() : second_break,
                       std::string(" uniform highp int ") + kLoopBudgetUniform +
                           "; highp int kit_loop_count_ = 0; bool kit_loop_go_() { kit_loop_count_ += 1; "
                           "return kit_loop_count_ <= max(" + kLoopBudgetUniform + ", " +
                           std::to_string(kLoopIterationsPerInvocation) + "); }");
  // Last offset first, and at one offset the later insert first, so each lands where it was meant.
  std::reverse(inserts.begin(), inserts.end());
  std::stable_sort(inserts.begin(), inserts.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
  std::string out = text;
  for (const auto& [offset, insert] : inserts) out.insert(offset, insert);
  shader.text = std::move(out);
}

}  // namespace kit
