// The shader include resolver (common/gl/shader_source.*): name rules, confinement
// to the shader folders, once-only inclusion, #version rules, file checks, and
// compile/link errors mapped back to the file and line that caused them.
#include <gtest/gtest.h>

#include <algorithm>
#include <iterator>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "base/error.h"
#include "gl/gl_objects.h"
#include "gl/loop_guard.h"
#include "render/interface_check.h"
#include "kit_test.h"
#include "kit_test_files.h"
#include "gl/shader_source.h"
#include "render/stages.h"

namespace fs = std::filesystem;
using kit::ShaderFolder;
using kit::ShaderLibrary;

namespace {

const std::string kVersion = std::string(kit::kRequiredVersionLine) + "\n";

// How often `needle` occurs in `text`.
size_t count_of(const std::string& text, const std::string& needle) {
  size_t count = 0;
  for (size_t at = text.find(needle); at != std::string::npos; at = text.find(needle, at + needle.size())) ++count;
  return count;
}

// The kit::Error message `f` throws; fails the test when it throws nothing.
template <typename F>
std::string error_of(F&& f) {
  try {
    f();
  } catch (const kit::Error& e) {
    return e.what();
  }
  ADD_FAILURE() << "expected a kit::Error, nothing was thrown";
  return "";
}

// A temp folder per test holding shader folders; `folder(name)` creates one.
class ShaderSourceTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    root_ = kit::test::temp_dir(std::string("shader_source/") + info->name());
  }
  fs::path folder(const std::string& name) {
    fs::create_directories(root_ / name);
    return root_ / name;
  }
  void write(const std::string& folder_name, const std::string& file, const std::string& text) {
    kit::test::write_file(folder(folder_name) / file, text);
  }
  // A library over the named folders, labelled by their names, in this order.
  ShaderLibrary library(const std::vector<std::string>& names) {
    std::vector<ShaderFolder> folders;
    for (const auto& n : names) folders.push_back({folder(n), n, {}});
    return ShaderLibrary(folders);
  }
  fs::path root_;
};

// Suite names start with the file's name (ShaderSource, ShaderSourceGl, ...).
using ShaderSource = ShaderSourceTest;

TEST_F(ShaderSource, PlainNamesResolveInFolderOrder) {
  write("lab", "shared.glsl", "// lab copy\n");
  write("base", "shared.glsl", "// base copy\n");
  write("base", "only_base.glsl", "// base only\n");
  ShaderLibrary lib = library({"lab", "base"});
  std::string display;
  EXPECT_EQ(lib.locate("shared.glsl", &display), fs::canonical(root_ / "lab" / "shared.glsl"));
  EXPECT_EQ(display, "lab/shared.glsl");
  EXPECT_EQ(lib.locate("only_base.glsl", &display), fs::canonical(root_ / "base" / "only_base.glsl"));
  EXPECT_EQ(display, "base/only_base.glsl");
  // Reversed order: the other copy wins.
  ShaderLibrary reversed = library({"base", "lab"});
  EXPECT_EQ(reversed.locate("shared.glsl"), fs::canonical(root_ / "base" / "shared.glsl"));
  // Includes resolve the same way.
  write("lab", "main.frag", kVersion + "#include \"shared.glsl\"\n#include \"only_base.glsl\"\nvoid main() {}\n");
  kit::AssembledShader s = lib.assemble("main.frag");
  EXPECT_NE(s.text.find("// lab copy"), std::string::npos);
  EXPECT_EQ(s.text.find("// base copy"), std::string::npos);
  EXPECT_NE(s.text.find("// base only"), std::string::npos);
  EXPECT_EQ(s.files, (std::vector<std::string>{"lab/main.frag", "lab/shared.glsl", "base/only_base.glsl"}));
  EXPECT_NE(error_of([&] { lib.locate("absent.glsl"); }).find("not found in lab, base"), std::string::npos);
}

TEST_F(ShaderSource, NamesThatCouldLeaveTheFoldersAreRefused) {
  write("lab", "x.glsl", "// x\n");
  write("lab/sub", "x.glsl", "// nested\n");
  ShaderLibrary lib = library({"lab"});
  for (const std::string name : {"../x.glsl", "../lab/x.glsl", "/etc/passwd", "sub/x.glsl", "sub\\x.glsl", "..", ".hidden", ""}) {
    std::string message = error_of([&] { lib.locate(name); });
    EXPECT_NE(message.find("is refused"), std::string::npos) << "name '" << name << "': " << message;
    EXPECT_NE(message.find("no '/'"), std::string::npos) << message;
    EXPECT_FALSE(kit::is_plain_shader_name(name)) << name;
  }
  for (const std::string name : {"x.glsl", "gbuffer_layout.h", "brdf-v2.glsl"})
    EXPECT_TRUE(kit::is_plain_shader_name(name)) << name;
  // The same rule through #include, reported at the including line.
  write("lab", "main.frag", kVersion + "// comment\n#include \"../x.glsl\"\nvoid main() {}\n");
  std::string message = error_of([&] { lib.assemble("main.frag"); });
  EXPECT_NE(message.find("lab/main.frag:3"), std::string::npos) << message;
  EXPECT_NE(message.find("is refused"), std::string::npos) << message;
}

TEST_F(ShaderSource, SymlinkLeavingItsFolderIsRefused) {
  write("outside", "secret.glsl", "// secret\n");
  write("lab", "target.glsl", "// inside\n");
  fs::create_symlink(root_ / "outside" / "secret.glsl", root_ / "lab" / "secret.glsl");
  fs::create_symlink("target.glsl", root_ / "lab" / "alias.glsl");  // stays inside: allowed
  ShaderLibrary lib = library({"lab"});
  std::string message = error_of([&] { lib.locate("secret.glsl"); });
  EXPECT_NE(message.find("lab/secret.glsl"), std::string::npos) << message;
  EXPECT_NE(message.find("links outside its folder"), std::string::npos) << message;
  EXPECT_EQ(lib.locate("alias.glsl"), fs::canonical(root_ / "lab" / "target.glsl"));
  // A symlinked folder entry pointing outside is refused the same way.
  fs::create_directory_symlink(root_ / "outside", root_ / "lab" / "dir.glsl");
  EXPECT_NE(error_of([&] { lib.locate("dir.glsl"); }).find("links outside its folder"), std::string::npos);
}

TEST_F(ShaderSource, EachFileIsIncludedOnceAndCyclesEnd) {
  write("lab", "common.glsl", "// COMMON\n");
  write("lab", "a.glsl", "// A\n#include \"common.glsl\"\n#include \"b.glsl\"\n");
  write("lab", "b.glsl", "// B\n#include \"a.glsl\"\n#include \"common.glsl\"\n");
  write("lab", "main.frag", kVersion + "#include \"common.glsl\"\n#include \"a.glsl\"\n#include \"common.glsl\"\nvoid main() {}\n");
  kit::AssembledShader s = library({"lab"}).assemble("main.frag");
  EXPECT_EQ(count_of(s.text, "// COMMON"), 1u) << s.text;
  EXPECT_EQ(count_of(s.text, "// A"), 1u) << s.text;
  EXPECT_EQ(count_of(s.text, "// B"), 1u) << s.text;
  EXPECT_EQ(count_of(s.text, "#include"), 0u) << s.text;
  // Every assembled line maps to its file and line: "// B" is line 1 of b.glsl.
  ASSERT_EQ(s.lines.size(), static_cast<size_t>(count_of(s.text, "\n")));
  size_t b_line = static_cast<size_t>(count_of(s.text.substr(0, s.text.find("// B")), "\n"));
  EXPECT_EQ(s.files[static_cast<size_t>(s.lines[b_line].file)], "lab/b.glsl");
  EXPECT_EQ(s.lines[b_line].line, 1);
}

TEST_F(ShaderSource, IncludeNestingIsLimited) {
  constexpr int kChain = 40;  // well past any sensible depth
  for (int i = 0; i < kChain; ++i)
    write("lab", "n" + std::to_string(i) + ".glsl", "#include \"n" + std::to_string(i + 1) + ".glsl\"\n");
  write("lab", "n" + std::to_string(kChain) + ".glsl", "// end\n");
  write("lab", "main.frag", kVersion + "#include \"n0.glsl\"\nvoid main() {}\n");
  std::string message = error_of([&] { library({"lab"}).assemble("main.frag"); });
  EXPECT_NE(message.find("nesting deeper than"), std::string::npos) << message;
}

TEST_F(ShaderSource, VersionLineRules) {
  ShaderLibrary lib = library({"lab"});
  write("lab", "versioned.glsl", kVersion + "// helper\n");
  write("lab", "includes_versioned.frag", kVersion + "#include \"versioned.glsl\"\nvoid main() {}\n");
  std::string message = error_of([&] { lib.assemble("includes_versioned.frag"); });
  EXPECT_NE(message.find("lab/versioned.glsl:1"), std::string::npos) << message;
  EXPECT_NE(message.find("must not declare #version"), std::string::npos) << message;

  const std::pair<std::string, std::string> bad_tops[] = {
      {"no_version.frag", "void main() {}\n"},
      {"late_version.frag", "void main() {}\n" + kVersion},
      {"wrong_version.frag", "#version 450 core\nvoid main() {}\n"},
      {"compat_version.frag", "#version 330\nvoid main() {}\n"},
      {"include_first.frag", "#include \"plain.glsl\"\n" + kVersion + "void main() {}\n"},
  };
  write("lab", "plain.glsl", "// no version\n");
  for (const auto& [name, text] : bad_tops) {
    write("lab", name, text);
    std::string m = error_of([&] { lib.assemble(name); });
    EXPECT_NE(m.find("lab/" + name), std::string::npos) << m;
    EXPECT_NE(m.find("the first line must be \"#version 330 core\""), std::string::npos) << name << ": " << m;
  }
  // Blank lines before the #version line are fine.
  write("lab", "blank_first.frag", "\n\n" + kVersion + "void main() {}\n");
  EXPECT_NO_THROW(lib.assemble("blank_first.frag"));
}

TEST_F(ShaderSource, FileContentChecks) {
  ShaderLibrary lib = library({"lab"});
  const std::pair<std::string, std::string> cases[] = {
      {"empty.glsl", ""},
      {"blank.glsl", " \n\t\r\n"},
      {"binary.glsl", std::string("// text\0more\n", 13)},
      {"latin1.glsl", "// caf\xe9\n"},
      {"truncated_utf8.glsl", "// \xe2\x82"},
  };
  const char* expected[] = {"file is empty", "file is empty", "binary data (a NUL byte)",
                            "not UTF-8 text (invalid byte at offset 6)", "not UTF-8 text (invalid byte at offset 3)"};
  for (size_t i = 0; i < std::size(cases); ++i) {
    write("lab", cases[i].first, cases[i].second);
    std::string m = error_of([&] { kit::read_shader_text(root_ / "lab" / cases[i].first, "lab/" + cases[i].first); });
    EXPECT_NE(m.find("lab/" + cases[i].first + ": "), std::string::npos) << m;
    EXPECT_NE(m.find(expected[i]), std::string::npos) << cases[i].first << ": " << m;
  }
  // Valid multi-byte UTF-8 passes.
  write("lab", "utf8.glsl", "// caf\xc3\xa9 \xe2\x82\xac \xf0\x9f\x98\x80\n");
  EXPECT_NO_THROW(kit::read_shader_text(root_ / "lab" / "utf8.glsl", "lab/utf8.glsl"));

  // The size limit: exactly kMaxShaderFileBytes is accepted, one byte more is not
  // (in comment lines of 64 bytes: a line has its own limit, tested below).
  std::string at_limit = kVersion + "void main() {}\n";
  while (at_limit.size() < kit::kMaxShaderFileBytes) at_limit += "//" + std::string(61, 'x') + "\n";
  at_limit.resize(static_cast<size_t>(kit::kMaxShaderFileBytes), 'x');
  write("lab", "at_limit.frag", at_limit);
  EXPECT_NO_THROW(lib.assemble("at_limit.frag"));
  write("lab", "over_limit.frag", at_limit + "x");
  std::string m = error_of([&] { lib.assemble("over_limit.frag"); });
  EXPECT_NE(m.find("lab/over_limit.frag"), std::string::npos) << m;
  EXPECT_NE(m.find("over the " + std::to_string(kit::kMaxShaderFileBytes) + "-byte limit"), std::string::npos) << m;

  // The checks apply to included files too, named by their own display name.
  write("lab", "main.frag", kVersion + "#include \"binary.glsl\"\nvoid main() {}\n");
  m = error_of([&] { lib.assemble("main.frag"); });
  EXPECT_NE(m.find("lab/binary.glsl: file holds binary data"), std::string::npos) << m;
  // A folder is not a shader file.
  fs::create_directories(root_ / "lab" / "folder.glsl");
  EXPECT_NE(error_of([&] { lib.locate("folder.glsl"); }).find("not a regular file"), std::string::npos);
}

// A UTF-8 byte-order mark (Notepad and some Windows editors write one) is dropped:
// the #version line behind it is the first line, and the text equals the file's without it.
TEST_F(ShaderSource, ByteOrderMarkIsDropped) {
  const std::string bom = "\xEF\xBB\xBF";
  const std::string body = kVersion + "#include \"common.glsl\"\nvoid main() {}\n";
  write("plain", "main.frag", body);
  write("plain", "common.glsl", "// common\n");
  write("bom", "main.frag", bom + body);
  write("bom", "common.glsl", bom + "// common\n");
  kit::AssembledShader plain = library({"plain"}).assemble("main.frag");
  kit::AssembledShader with_bom;
  EXPECT_NO_THROW(with_bom = library({"bom"}).assemble("main.frag"));
  EXPECT_EQ(with_bom.text, plain.text);
  EXPECT_EQ(with_bom.text.find(bom), std::string::npos);
  EXPECT_EQ(kit::read_shader_text(root_ / "bom" / "common.glsl", "bom/common.glsl"), "// common\n");
  // A mark and nothing else is still an empty file; a mark later in the text is kept (valid UTF-8).
  write("bom", "only_bom.glsl", bom + "\n");
  EXPECT_NE(error_of([&] { kit::read_shader_text(root_ / "bom" / "only_bom.glsl", "bom/only_bom.glsl"); })
                .find("bom/only_bom.glsl: file is empty"), std::string::npos);
  write("bom", "inner.glsl", "// x" + bom + "\n");
  EXPECT_EQ(kit::read_shader_text(root_ / "bom" / "inner.glsl", "bom/inner.glsl"), "// x" + bom + "\n");
}

// One very long line used to overflow the stack: the #version and #include
// lines were matched with std::regex, which recurses once per character (a line
// of 200,000 spaces took ~131,000 frames; an input written for the fuzz harnesses).
// A line longer than kMaxShaderLineBytes is now refused naming its file and line,
// in the file's own checks, so the grader refuses it the same way.
TEST_F(ShaderSource, LongLinesAreRefusedWithTheirFileAndLine) {
  ShaderLibrary lib = library({"lab"});
  const std::string limit = std::to_string(kit::kMaxShaderLineBytes);
  const std::string spaces(200000, ' ');
  const std::string version_line = kit::kRequiredVersionLine, include_line = "#include \"x.glsl\"";
  struct Case {
    std::string file, text, where;
    size_t length;
  };
  const Case cases[] = {
      {"spaces.frag", kVersion + spaces + "\nvoid main() {}\n", "lab/spaces.frag:2: ", spaces.size()},
      {"version.frag", version_line + spaces + "\nvoid main() {}\n", "lab/version.frag:1: ",
       version_line.size() + spaces.size()},
      {"include.frag", kVersion + include_line + spaces + "\nvoid main() {}\n", "lab/include.frag:2: ",
       include_line.size() + spaces.size()},
      {"crlf.frag", kVersion + "\r\n" + std::string(kit::kMaxShaderLineBytes + 1, 'x') + "\r\n", "lab/crlf.frag:3: ",
       kit::kMaxShaderLineBytes + 1},
  };
  for (const Case& c : cases) {
    write("lab", c.file, c.text);
    std::string m = error_of([&] { lib.assemble(c.file); });
    EXPECT_NE(m.find(c.where + "line is " + std::to_string(c.length) + " bytes long, over the " + limit + "-byte limit"),
              std::string::npos) << m;
  }
  // In an included file, the message names the included file and its line.
  write("lab", "long.glsl", "// helper\n// helper\n" + spaces + "\n");
  write("lab", "main.frag", kVersion + "#include \"long.glsl\"\nvoid main() {}\n");
  std::string m = error_of([&] { lib.assemble("main.frag"); });
  EXPECT_NE(m.find("lab/main.frag:2: in #include \"long.glsl\": lab/long.glsl:3: line is 200000 bytes long"),
            std::string::npos) << m;
  // Exactly at the limit (its CR LF not counted) is accepted; the check is the reader's, so the grader applies it too.
  write("lab", "at_limit.frag", kVersion + "//" + std::string(kit::kMaxShaderLineBytes - 2, 'x') + "\r\nvoid main() {}\n");
  EXPECT_NO_THROW(lib.assemble("at_limit.frag"));
  write("lab", "over.glsl", std::string(kit::kMaxShaderLineBytes + 1, 'x'));
  m = error_of([&] { kit::read_shader_text(root_ / "lab" / "over.glsl", "lab/over.glsl"); });
  EXPECT_NE(m.find("lab/over.glsl:1: line is " + std::to_string(kit::kMaxShaderLineBytes + 1) + " bytes long"),
            std::string::npos) << m;
}

// A file whose #defines expand exponentially (each macro naming the one before twice) is
// refused by its file, line and macro before any GL compile; the same macros used a little
// (the witness that the bound is not the file's size) and function-like ones are sized too.
TEST_F(ShaderSource, MacrosThatExpandExponentiallyAreRefusedByLine) {
  ShaderLibrary lib = library({"lab"});
  std::string bomb = "#define M0 x\n";
  for (int i = 1; i <= 30; ++i) bomb += "#define M" + std::to_string(i) + " M" + std::to_string(i - 1) + " M" +
                                         std::to_string(i - 1) + "\n";
  write("lab", "bomb.glsl", bomb);
  write("lab", "main.frag", kVersion + "#include \"bomb.glsl\"\nout vec4 o;\nvoid main() {\n    float M30 = 0.0;\n}\n");
  std::string m = error_of([&] { lib.assemble("main.frag"); });
  EXPECT_NE(m.find("lab/main.frag:5: M30 expands to more than 65536 tokens on this line"), std::string::npos) << m;
  // Defined but never used: nothing expands, nothing is refused.
  write("lab", "unused.frag", kVersion + "#include \"bomb.glsl\"\nout vec4 o;\nvoid main() {}\n");
  EXPECT_NO_THROW(lib.assemble("unused.frag"));
  // M15 (32768 tokens) once is under the line's limit; in 40 lines it passes the shader's.
  write("lab", "some.frag", kVersion + "#include \"bomb.glsl\"\nvoid main() {\n    M15;\n}\n");
  EXPECT_NO_THROW(lib.assemble("some.frag"));
  std::string many = kVersion + "#include \"bomb.glsl\"\nvoid main() {\n";
  for (int i = 0; i < 40; ++i) many += "    M15;\n";
  write("lab", "many.frag", many + "}\n");
  m = error_of([&] { lib.assemble("many.frag"); });
  EXPECT_NE(m.find("lab/many.frag:35: the shader's macros expand to more than 1048576 tokens"), std::string::npos) << m;
  // Function-like macros double the same way; #undef forgets one.
  write("lab", "calls.frag", kVersion + "#define F0(a) (a + 1.0)\n#define F1(a) F0(a) * F0(a)\n" +
                                 [] { std::string t; for (int i = 2; i <= 24; ++i) t += "#define F" + std::to_string(i) + "(a) F" + std::to_string(i - 1) + "(a) * F" + std::to_string(i - 1) + "(a)\n"; return t; }() +
                                 "#undef F24\nfloat F24(float a) { return a; }\nvoid main() { float y = F23(2.0); }\n");
  m = error_of([&] { lib.assemble("calls.frag"); });
  EXPECT_NE(m.find("lab/calls.frag:29: F23 expands to more than 65536 tokens"), std::string::npos) << m;
}

// The kit's own shaders, as every stage assembles them, are far inside both bounds.
TEST_F(ShaderSource, TheKitsShadersAreFarUnderTheMacroBounds) {
  for (const kit::Stage& stage : kit::stages()) {
    if (!fs::is_directory(kit::kit_root() / "solutions" / stage.folder)) continue;
    ShaderLibrary lib = kit::stage_library(stage, kit::kit_root() / "solutions");
    for (const auto& entry : fs::directory_iterator(kit::kit_root() / "solutions" / stage.folder)) {
      if (entry.path().extension() != ".vert" && entry.path().extension() != ".frag") continue;
      const kit::AssembledShader shader = lib.assemble(entry.path().filename().string());
      // Bounds 64 times smaller still pass: the kit's own margin.
      EXPECT_NO_THROW(kit::check_macro_expansion(shader, kit::kMaxExpandedLineTokens / 64,
                                                 kit::kMaxExpandedShaderTokens / 64))
          << stage.folder << "/" << entry.path().filename().string();
    }
  }
}

// The directives are recognised as before the regex was replaced: spaces around
// the '#' of an include, a // comment after it, CR LF line ends; anything else is code.
TEST_F(ShaderSource, DirectiveSpellings) {
  write("lab", "a.glsl", "// a\n");
  write("lab", "b.glsl", "// b\n");
  write("lab", "main.frag", "#version 330 core\r\n#include \"a.glsl\" // why\r\n  #  include\t\"b.glsl\"\n"
                            "#include \"a.glsl\" /* no */\n#includes \"b.glsl\"\nvoid main() {}\n");
  kit::AssembledShader s = library({"lab"}).assemble("main.frag");
  EXPECT_EQ(s.files, (std::vector<std::string>{"lab/main.frag", "lab/a.glsl", "lab/b.glsl"}));
  // The include followed by a block comment and "#includes" are not includes: they stay in the text.
  EXPECT_NE(s.text.find("#include \"a.glsl\" /* no */"), std::string::npos) << s.text;
  EXPECT_NE(s.text.find("#includes \"b.glsl\""), std::string::npos) << s.text;
  // "#versions" is no version line: code before the version line.
  write("lab", "versions.frag", "#versions 330 core\nvoid main() {}\n");
  EXPECT_NE(error_of([&] { library({"lab"}).assemble("versions.frag"); }).find("the first line must be"),
            std::string::npos);
}

// The varying check (kit::check_stage_interfaces, run before every compile)
// rescanned the statement so far at each character: a file of 65,000 newlines,
// or of lines of text then lines of '}', took 10 to 30 s in the fuzz build and
// grew with the square of the size (an input written for the fuzz harnesses). Now one
// pass: these files, four times larger, are checked at once, and the mismatched
// input behind them is still found on its own line.
TEST_F(ShaderSource, VaryingCheckIsLinearInTheFileSize) {
  const kit::Stage& stage = kit::find_stage("gbuffer");  // lab 1: needs no earlier solution
  const fs::path lab_root = root_ / "labs";
  kit::test::write_file(lab_root / stage.folder / "gbuffer.vert",
                        kVersion + "out vec3 v_a;\nvoid main() { v_a = vec3(0.0); gl_Position = vec4(0.0); }\n");
  const std::string tail = "in vec3 v_b;\nout vec4 c;\nvoid main() { c = vec4(v_b, 1.0); }\n";
  const std::string a_lines = [] { std::string t; for (int i = 0; i < 60000; ++i) t += "a\n"; return t; }();
  const std::string brace_lines = [] { std::string t; for (int i = 0; i < 60000; ++i) t += "}\n"; return t; }();
  const std::pair<std::string, int> bodies[] = {
      {std::string(250000, '\n') + tail, 250002},                   // the line of `in vec3 v_b`
      {a_lines + brace_lines + ";\n" + tail, 120003},
  };
  for (const auto& [body, line] : bodies) {
    kit::test::write_file(lab_root / stage.folder / "gbuffer.frag", kVersion + body);
    ShaderLibrary lib = kit::stage_library(stage, lab_root);
    std::string m = error_of([&] { kit::check_stage_interfaces(stage, lib); });
    EXPECT_NE(m.find("labs/01-gbuffer/gbuffer.frag:" + std::to_string(line) + ": fragment shader input `v_b' has no "
                     "matching output"),
              std::string::npos) << m.substr(0, 400);
  }
}

TEST_F(ShaderSource, OnlyRestrictsAFolderToItsListedNames) {
  write("lab", "mine.glsl", "// lab mine\n");
  write("lab", "theirs.glsl", "// lab theirs\n");
  write("base", "theirs.glsl", "// base theirs\n");
  std::vector<ShaderFolder> folders = {{folder("lab"), "lab", {"mine.glsl"}}, {folder("base"), "base", {}}};
  ShaderLibrary lib(folders);
  EXPECT_EQ(lib.locate("mine.glsl"), fs::canonical(root_ / "lab" / "mine.glsl"));
  EXPECT_EQ(lib.locate("theirs.glsl"), fs::canonical(root_ / "base" / "theirs.glsl"));
  write("lab", "extra.glsl", "// lab extra\n");
  std::string m = error_of([&] { lib.locate("extra.glsl"); });
  EXPECT_NE(m.find("\"extra.glsl\" not found"), std::string::npos) << m;
}

// A grading child's libraries share an AssembledShaderCache: a shader is read once, however
// many libraries assemble it, and the defines, the folders and the name each make their own
// entry. Without the cache an edit is read (the witness that the cache is what keeps the text).
TEST_F(ShaderSource, AssembledCacheKeepsTextsByFoldersNameAndDefines) {
  write("lab", "main.frag", kVersion + "#include \"part.glsl\"\n#ifdef KIT_TEST_SWITCH\n#endif\n");
  write("lab", "part.glsl", "// part one\n");
  write("other", "main.frag", kVersion + "// the other folder's\n");
  kit::AssembledShaderCache cache;
  ShaderLibrary first = library({"lab"}), second = library({"lab"}), plain = library({"lab"});
  first.keep_assembled_in(&cache);
  second.keep_assembled_in(&cache);
  const kit::AssembledShader before = first.assemble("main.frag");
  ASSERT_NE(before.text.find("// part one"), std::string::npos) << before.text;
  write("lab", "part.glsl", "// part two\n");
  EXPECT_EQ(second.assemble("main.frag").text, before.text);  // kept: not read again
  EXPECT_EQ(second.assemble("main.frag").files, before.files);
  EXPECT_NE(plain.assemble("main.frag").text.find("// part two"), std::string::npos);  // no cache: read
  second.set_define("KIT_TEST_SWITCH", true);  // another text: assembled, reading the edit
  const std::string defined = second.assemble("main.frag").text;
  EXPECT_NE(defined.find("#define KIT_TEST_SWITCH\n"), std::string::npos) << defined;
  EXPECT_NE(defined.find("// part two"), std::string::npos) << defined;
  ShaderLibrary other = library({"other"});
  other.keep_assembled_in(&cache);
  EXPECT_NE(other.assemble("main.frag").text.find("the other folder's"), std::string::npos);
}

TEST(ShaderSourceLog, MesaAndNvidiaLinesMapToFiles) {
  kit::AssembledShader s;
  s.files = {"lab/main.frag", "lab/brdf.glsl"};
  s.lines = {{0, 1}, {1, 1}, {1, 2}, {0, 3}};
  EXPECT_EQ(s.map_log("0:3(7): error: `x' undeclared"), "lab/brdf.glsl:2:7: error: `x' undeclared\n");
  EXPECT_EQ(s.map_log("0(4) : error C1008: undefined variable"), "lab/main.frag:3 : error C1008: undefined variable\n");
  EXPECT_EQ(s.map_log("0:99(1): error: past the end"), "lab/main.frag:?:1: error: past the end\n");
  EXPECT_EQ(s.map_log("warning without a location"), "warning without a location\n");
}

// The log parser used to be std::regex too: a long run of digits overflowed the
// stack, and a line number past INT_MAX threw std::out_of_range out of std::stoi
// (an input written for the fuzz harnesses). Both now map like any line past the end.
TEST(ShaderSourceLog, HostileLogLinesMapWithoutThrowing) {
  kit::AssembledShader s;
  s.files = {"lab/main.frag"};
  s.lines = {{0, 1}};
  const std::string digits(200000, '1');
  EXPECT_EQ(s.map_log(digits), digits + "\n");
  EXPECT_EQ(s.map_log("0:99999999999999999999(3): error: x"), "lab/main.frag:?:3: error: x\n");
  EXPECT_EQ(s.map_log("0(99999999999) : error"), "lab/main.frag:? : error\n");
  EXPECT_EQ(s.map_log("0:" + digits + "(" + digits + ")"), "lab/main.frag:?:" + digits + "\n");
  EXPECT_EQ(s.map_log("0:1(2"), "0:1(2\n");
  EXPECT_EQ(s.map_log("0:1(2)"), "lab/main.frag:1:2\n");
}

// Where a uniform the framework never sets is reported (Program::declaration_site):
// the first line with the word "uniform" and later, before any ';', the uniform's name
// as a whole word. It was the regex \buniform\b[^;]*\bNAME\b; these are its answers.
TEST(ShaderSourceUniform, DeclarationLinesAreFoundByWholeWords) {
  for (const std::string line : {"uniform float u_x;", "  uniform vec3 u_a, u_x;", "layout(std140) uniform\tvec4 u_x[2];",
                                 "uniform sampler2D u_x", "uniform float u_y; uniform float u_x;", "x uniform u_x"})
    EXPECT_TRUE(kit::declares_uniform(line, "u_x")) << line;
  for (const std::string line : {"uniform float u_xy;", "uniform float u_y; float u_x;", "uniforms float u_x;",
                                 "my_uniform float u_x;", "float u_x; // uniform", "uniform float u_x2;", "", "u_x uniform"})
    EXPECT_FALSE(kit::declares_uniform(line, "u_x")) << line;
  EXPECT_TRUE(kit::declares_uniform("uniform Light u_lights[4];", "u_lights"));
  EXPECT_FALSE(kit::declares_uniform(std::string(100000, 'u') + " uniform", "u_x"));
}

// Compile and link errors need a GL context.
class ShaderProgramTest : public ShaderSourceTest {
 protected:
  void SetUp() override {
    ShaderSourceTest::SetUp();
    kit::test::context();
  }
  // The test's "lab" folder first, then the kit's shaders/ (fullscreen.vert, uniforms).
  ShaderLibrary lab_then_kit() {
    return ShaderLibrary({{folder("lab"), "lab", {}}, {kit::shaders_dir(), "shaders", {}}});
  }
};

using ShaderSourceGl = ShaderProgramTest;

TEST_F(ShaderSourceGl, CompileErrorNamesTheIncludedFileAndLine) {
  constexpr int kErrorLine = 4;  // the line of brdf.glsl below that uses an undeclared name
  write("lab", "brdf.glsl",
        "// a helper with a mistake\n"
        "#include \"math.glsl\"\n"
        "vec3 shade() {\n"
        "    return vec3(kit_undeclared_name * KIT_PI);\n"
        "}\n");
  write("lab", "main.frag", kVersion + "#include \"uniforms.glsl\"\n#include \"brdf.glsl\"\nout vec4 c;\nvoid main() { c = vec4(shade(), 1.0); }\n");
  ShaderLibrary lib = lab_then_kit();
  std::string m = error_of([&] { kit::Program(lib, "fullscreen.vert", "main.frag"); });
  EXPECT_NE(m.find("compile error in lab/main.frag"), std::string::npos) << m;
  EXPECT_NE(m.find("lab/brdf.glsl:" + std::to_string(kErrorLine) + ":"), std::string::npos) << m;
  EXPECT_NE(m.find("kit_undeclared_name"), std::string::npos) << m;
  EXPECT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));

  // Fixing the line makes the same library compile, so the error above came from it.
  write("lab", "brdf.glsl", "#include \"math.glsl\"\nvec3 shade() { return vec3(KIT_PI); }\n");
  kit::Program ok(lib, "fullscreen.vert", "main.frag");
  EXPECT_TRUE(ok.valid());
  EXPECT_EQ(ok.source_paths().size(), 7u);  // fullscreen.vert; main.frag, uniforms, layout, camera, brdf, math
}

// A framework define reaches only the shaders that name it: the others assemble to the
// same text with or without it, so a define change (the lights, the attenuation model)
// rebuilds only the programs it can change (Program::built_from).
TEST_F(ShaderSourceGl, DefinesReachOnlyTheShadersThatNameThem) {
  write("lab", "uses.frag", kVersion + "out vec4 c;\nvoid main() {\n#ifdef KIT_TEST_SWITCH\n  c = vec4(1.0);\n#else\n"
                                       "  c = vec4(0.0);\n#endif\n}\n");
  write("lab", "ignores.frag", kVersion + "out vec4 c;\n// KIT_TEST_SWITCHES is another word\nvoid main() { c = vec4(0.5); }\n");
  ShaderLibrary lib = lab_then_kit();
  const kit::Program uses(lib, "fullscreen.vert", "uses.frag");
  const kit::Program ignores(lib, "fullscreen.vert", "ignores.frag");
  const std::string ignores_before = lib.assemble("ignores.frag").text;
  lib.set_define("KIT_TEST_SWITCH", true);
  EXPECT_NE(lib.assemble("uses.frag").text.find("#define KIT_TEST_SWITCH\n"), std::string::npos);
  EXPECT_EQ(lib.assemble("ignores.frag").text, ignores_before);
  EXPECT_FALSE(uses.built_from(lib, "fullscreen.vert", "uses.frag"));
  EXPECT_TRUE(ignores.built_from(lib, "fullscreen.vert", "ignores.frag"));
  lib.set_define("KIT_TEST_SWITCH", false);
  EXPECT_TRUE(uses.built_from(lib, "fullscreen.vert", "uses.frag"));
  // An edit is a change too (the viewer's hot reload rebuilds what it reaches).
  write("lab", "ignores.frag", kVersion + "out vec4 c;\nvoid main() { c = vec4(0.25); }\n");
  EXPECT_FALSE(ignores.built_from(lib, "fullscreen.vert", "ignores.frag"));
}

// Below kMaxShaderLineBytes a long line is an ordinary line: a 4000-byte
// expression compiles and links (the witness that the limit refuses nothing real).
TEST_F(ShaderSourceGl, LongLineUnderTheLimitCompiles) {
  std::string sum = "    c = vec4(0.0";
  while (sum.size() < 4000) sum += " + 0.001";
  sum += ", 0.0, 0.0, 1.0);";
  ASSERT_LT(sum.size(), kit::kMaxShaderLineBytes);
  ASSERT_GE(sum.size(), 4000u);
  write("lab", "long_line.frag", kVersion + "out vec4 c;\nvoid main() {\n" + sum + "\n}\n");
  kit::Program program(lab_then_kit(), "fullscreen.vert", "long_line.frag");
  EXPECT_TRUE(program.valid());
  EXPECT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));
}

TEST_F(ShaderSourceGl, LinkErrorIsReported) {
  // Declared, called, never defined: each stage compiles, the program cannot link.
  write("lab", "link.frag", kVersion + "vec3 kit_missing_helper();\nout vec4 c;\nvoid main() { c = vec4(kit_missing_helper(), 1.0); }\n");
  std::string m = error_of([&] { kit::Program(lab_then_kit(), "fullscreen.vert", "link.frag"); });
  EXPECT_NE(m.find("link error (shaders/fullscreen.vert + lab/link.frag)"), std::string::npos) << m;
  EXPECT_NE(m.find("kit_missing_helper"), std::string::npos) << m;
  EXPECT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));
}

// The guarded loops on a GL that compiles GLSL ES 3.00 (Mesa's, as a browser's would): a
// loop that never ends stops after the pass's budget, exactly; a loop under it runs as
// written. Witness: the same loop for the desktop, unguarded, runs past the budget. (The
// budget here stays under llvmpipe's own cap, 65,535 iterations a loop, which ends an
// endless loop on the desktop, slowly: kit-grade's CPU limit is what stops it there.)
TEST_F(ShaderSourceGl, GuardedLoopsStopAtTheBudget) {
  constexpr int kSize = 128;  // a 128x128 pass: 2^28 / 16384 = 16,384 iterations a pixel
  const int budget = kit::loop_budget(kSize, kSize);
  ASSERT_EQ(budget, 16384);
  auto count = [&](const std::string& body, kit::ShaderTarget target) {
    write("lab", "count.frag", kVersion + "out vec4 c;\nvoid main() {\n  float n = 0.0;\n" + body + "\n  c = vec4(n);\n}\n");
    ShaderLibrary lib = lab_then_kit();
    lib.set_target(target);
    const kit::Program program(lib, "fullscreen.vert", "count.frag");
    const kit::Texture2D target_texture(kSize, kSize, kit::TextureFormat{GL_RGBA32F, GL_RGBA, GL_FLOAT});
    kit::Framebuffer fbo;
    fbo.attach_color(0, target_texture);
    fbo.set_draw_buffers(1);
    kit::FullscreenTriangle().pass(program, fbo, kSize, kSize);
    std::vector<float> pixels(4u * kSize * kSize);
    glReadPixels(0, 0, kSize, kSize, GL_RGBA, GL_FLOAT, pixels.data());
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    EXPECT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));
    const auto [lo, hi] = std::minmax_element(pixels.begin(), pixels.end());
    EXPECT_EQ(*lo, *hi) << body;
    return static_cast<double>(*hi);
  };
  const kit::ShaderTarget es = kit::ShaderTarget::GlslEs300;
  EXPECT_EQ(count("  while (n >= 0.0) n += 1.0;", es), budget);
  EXPECT_EQ(count("  for (;;) n += 1.0;", es), budget);
  EXPECT_EQ(count("  do { n += 1.0; } while (true);", es), budget + 1);  // a do loop's first asks nothing
  // Nested: the budget counts every loop of the invocation together.
  EXPECT_EQ(count("  for (int i = 0; i < 1000; ++i) for (int j = 0; j < 1000; ++j) n += 1.0;", es),
            budget - 17);  // 17 outer iterations began (each counted), the 17th's inner loop cut
  EXPECT_EQ(count("  for (int i = 0; i < 100; ++i) n += 1.0;", es), 100.0);
  EXPECT_EQ(count("  for (int i = 0; i < 20000; ++i) n += 1.0;", es), budget);
  EXPECT_EQ(count("  for (int i = 0; i < 20000; ++i) n += 1.0;", kit::ShaderTarget::Glsl330Core), 20000.0);
}

// GLSL ES 3.00 for the browser build (translate_to_glsl_es): plain text, so tested here
// on the desktop through a library whose target is set to it.
using ShaderSourceEs = ShaderSourceTest;

TEST_F(ShaderSourceEs, DesktopTargetKeepsTheTextAsWritten) {
  write("lab", "main.frag", kVersion + "out vec4 c;\nvoid main() { c = vec4(1.0); }\n");
  ShaderLibrary lib = library({"lab"});
  EXPECT_EQ(lib.target(), kit::ShaderTarget::Glsl330Core);
  EXPECT_EQ(lib.assemble("main.frag").text, kVersion + "out vec4 c;\nvoid main() { c = vec4(1.0); }\n");
}

TEST_F(ShaderSourceEs, VersionLineAndPrecisionsWithoutShiftingLines) {
  write("lab", "inc.glsl", "float helper() { return 1.0; }\n");
  write("lab", "main.frag", kVersion + "#include \"inc.glsl\"\nout vec4 c;\nvoid main() { c = vec4(helper()); }\n");
  ShaderLibrary lib = library({"lab"});
  lib.set_target(kit::ShaderTarget::GlslEs300);
  lib.set_define("KIT_SWITCH", true);  // named nowhere: no #define line
  const kit::AssembledShader s = lib.assemble("main.frag");
  const std::string expected = std::string(kit::kGlslEsVersionLine) + "\n" + kit::kGlslEsPrecisions + "\n" +
                               "float helper() { return 1.0; }\nout vec4 c;\nvoid main() { c = vec4(helper()); }\n";
  EXPECT_EQ(s.text, expected);
  ASSERT_EQ(s.lines.size(), 5u);
  // The precision line counts as the version line; the rest keep their files and lines.
  EXPECT_EQ(s.map_log("0:2(1): error: a"), "lab/main.frag:1:1: error: a\n");
  EXPECT_EQ(s.map_log("0:3(5): error: b"), "lab/inc.glsl:1:5: error: b\n");
  EXPECT_EQ(s.map_log("0:5(1): error: c"), "lab/main.frag:4:1: error: c\n");
  // ANGLE, WebGL's compiler, writes "ERROR: 0:LINE: ...".
  EXPECT_EQ(s.map_log("ERROR: 0:4: 'c' : undeclared identifier"), "lab/main.frag:3: error: 'c' : undeclared identifier\n");
  EXPECT_EQ(s.map_log("WARNING: 0:3: 'x' : unused"), "lab/inc.glsl:1: warning: 'x' : unused\n");
}

TEST_F(ShaderSourceEs, DefinesStayAfterTheVersionLine) {
  write("lab", "main.frag", kVersion + "#ifdef KIT_SWITCH\nout vec4 c;\n#endif\nvoid main() {}\n");
  ShaderLibrary lib = library({"lab"});
  lib.set_target(kit::ShaderTarget::GlslEs300);
  lib.set_define("KIT_SWITCH", true);
  const kit::AssembledShader s = lib.assemble("main.frag");
  EXPECT_EQ(s.text.rfind(std::string(kit::kGlslEsVersionLine) + "\n", 0), 0u) << s.text;
  EXPECT_NE(s.text.find("#define KIT_SWITCH\n"), std::string::npos) << s.text;
  EXPECT_EQ(s.map_log("0:4(1): error: d"), "lab/main.frag:2:1: error: d\n");
}

TEST_F(ShaderSourceEs, MissingConstructsAreRefusedByFileLineAndName) {
  write("lab", "inc.glsl", "// a sampler1D in a comment is fine\n/* and double\n here */ float f;\nuniform sampler1D ramp;\n");
  write("lab", "main.frag", kVersion + "#include \"inc.glsl\"\nvoid main() {}\n");
  ShaderLibrary lib = library({"lab"});
  lib.set_target(kit::ShaderTarget::GlslEs300);
  const std::string m = error_of([&] { lib.assemble("main.frag"); });
  EXPECT_NE(m.find("lab/inc.glsl:4: sampler1D is not in GLSL ES 3.00"), std::string::npos) << m;
  for (const std::string construct : {"double", "dvec3", "noperspective", "gl_ClipDistance", "texture1D", "samplerBuffer",
                                      "sampler2DRect", "gl_FragColor"}) {
    write("lab", "main.frag", kVersion + "void main() {\n  " + construct + " x;\n}\n");
    const std::string e = error_of([&] { lib.assemble("main.frag"); });
    EXPECT_NE(e.find("lab/main.frag:3: " + construct + " is not in GLSL ES 3.00"), std::string::npos) << e;
  }
  // A word that only contains a refused one is fine, as is the desktop target.
  write("lab", "main.frag", kVersion + "float doubled;\nvoid main() {}\n");
  EXPECT_NO_THROW(lib.assemble("main.frag"));
  lib.set_target(kit::ShaderTarget::Glsl330Core);
  write("lab", "main.frag", kVersion + "uniform sampler1D ramp;\nvoid main() {}\n");
  EXPECT_NO_THROW(lib.assemble("main.frag"));
}

TEST_F(ShaderSourceEs, EveryKitShaderTranslates) {
  // The kit's own shaders and every lab's solution, as the browser build assembles them.
  for (const kit::Stage& stage : kit::stages()) {
    if (!fs::is_directory(kit::kit_root() / "solutions" / stage.folder)) continue;
    ShaderLibrary lib = kit::stage_library(stage, kit::kit_root() / "solutions");
    lib.set_target(kit::ShaderTarget::GlslEs300);
    for (const auto& entry : fs::directory_iterator(kit::kit_root() / "solutions" / stage.folder)) {
      const std::string name = entry.path().filename().string();
      if (entry.path().extension() != ".vert" && entry.path().extension() != ".frag") continue;
      EXPECT_NO_THROW(lib.assemble(name)) << stage.folder << "/" << name;
    }
  }
}

// The loop guard (gl/loop_guard.h): every loop of a shader for WebGL2 asks the counter in
// its condition, on the lines it was written on.
TEST_F(ShaderSourceEs, LoopsAskTheCounterWithoutMovingALine) {
  write("lab", "loops.frag", kVersion +
                                 "out vec4 c;\n"
                                 "// while (forever) in a comment is left alone\n"
                                 "#define REPEAT(n) for (int r = 0; r < (n); ++r)\n"
                                 "void main() {\n"
                                 "  float x = 0.0;\n"
                                 "  for (int i = 0; i < int(max(1.0, 2.0)); i++) x += 1.0;\n"
                                 "  for (;;) { if (x > 3.0) break; x += 1.0; }\n"
                                 "  while (x < 10.0 || x > 20.0) x += 1.0;\n"
                                 "  do { x -= 1.0; } while (x > 5.0);\n"
                                 "  REPEAT(3) x += 1.0;\n"
                                 "  c = vec4(x);\n"
                                 "}\n");
  ShaderLibrary lib = library({"lab"});
  lib.set_target(kit::ShaderTarget::GlslEs300);
  const kit::AssembledShader s = lib.assemble("loops.frag");
  EXPECT_EQ(count_of(s.text, "\n"), 14u) << s.text;
  EXPECT_EQ(s.lines.size(), 14u);
  for (const std::string line :
       {"// while (forever) in a comment is left alone\n",
        "#define REPEAT(n) for (int r = 0; ( r < (n)) && kit_loop_go_(); ++r)\n",
        "  for (int i = 0; ( i < int(max(1.0, 2.0))) && kit_loop_go_(); i++) x += 1.0;\n",
        "  for (; kit_loop_go_();) { if (x > 3.0) break; x += 1.0; }\n",
        "  while ((x < 10.0 || x > 20.0) && kit_loop_go_()) x += 1.0;\n",
        "  do { x -= 1.0; } while ((x > 5.0) && kit_loop_go_());\n",
        "  REPEAT(3) x += 1.0;\n"})
    EXPECT_NE(s.text.find(line), std::string::npos) << line << "\nin\n" << s.text;
  // The counter, on the precision line, which counts as the version line.
  const size_t second_line = s.text.find('\n') + 1;
  EXPECT_NE(s.text.substr(second_line, s.text.find('\n', second_line) - second_line).find("bool kit_loop_go_()"),
            std::string::npos) << s.text;
  EXPECT_EQ(s.map_log("ERROR: 0:11: 'y' : undeclared identifier"), "lab/loops.frag:10: error: 'y' : undeclared identifier\n");

  // No loop, nothing added; the desktop's text is as written.
  write("lab", "plain.frag", kVersion + "out vec4 c;\nvoid main() { c = vec4(1.0); }\n");
  EXPECT_EQ(lib.assemble("plain.frag").text.find("kit_loop"), std::string::npos);
  lib.set_target(kit::ShaderTarget::Glsl330Core);
  EXPECT_EQ(lib.assemble("loops.frag").text.find("kit_loop"), std::string::npos);
}

TEST_F(ShaderSourceEs, LoopsTheGuardCannotSeeAreRefusedByLine) {
  ShaderLibrary lib = library({"lab"});
  lib.set_target(kit::ShaderTarget::GlslEs300);
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"#define KW while\nvoid main() { KW (true) {} }\n", "lab/main.frag:2: `while' without its condition"},
      {"#define CAT(a, b) a ## b\nvoid main() {}\n", "lab/main.frag:2: token pasting (##)"},
      {"#define LOOP(c) while (c\nvoid main() { LOOP(true)) {} }\n", "lab/main.frag:2: `while' whose parentheses"},
      {"void main() {\n  int kit_loop_count_ = 0;\n}\n", "lab/main.frag:3: the names starting with kit_loop_"},
      {"void main() {\n  for (int i = 0; i < 3) {}\n}\n", "lab/main.frag:3: `for' without two semicolons"},
      {"bool f();\nvoid main() {\n  while (bool go = f()) {}\n}\n", "lab/main.frag:4: `while' whose condition declares"},
      {"void main() {\n  for (;highp int k = 1;) {}\n}\n", "lab/main.frag:3: `for' whose condition declares"},
  };
  for (const auto& [text, expected] : cases) {
    write("lab", "main.frag", kVersion + text);
    const std::string m = error_of([&] { lib.assemble("main.frag"); });
    EXPECT_NE(m.find(expected), std::string::npos) << text << "\n" << m;
    EXPECT_NE(m.find("a loop that never ends cannot lock the page"), std::string::npos) << m;
  }
}

TEST(ShaderSourceLoopBudget, FrameSizedPassesAndLabSixsMaps) {
  EXPECT_EQ(kit::loop_budget(640, 480), kit::kLoopIterationsPerInvocation);
  EXPECT_EQ(kit::loop_budget(1920, 1080), kit::kLoopIterationsPerInvocation);
  // The irradiance map (32x16) sums 128x64 texels and 64 rows: 8,256 iterations a texel.
  EXPECT_GE(kit::loop_budget(32, 16), 128 * 64 + 64);
  // The prefiltered map's first level (256x128), 256 samples a texel; the BRDF table (64x64), 512.
  EXPECT_GE(kit::loop_budget(256, 128), 256);
  EXPECT_GE(kit::loop_budget(64, 64), 512);
  EXPECT_EQ(kit::loop_budget(0, 0), static_cast<int>(kit::kLoopIterationsPerPass));
}

}  // namespace
