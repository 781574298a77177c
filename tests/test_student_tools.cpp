// kit-render behaves for a student as the grader does: it renders labs/ by
// default (--solution: the solutions), takes a lab folder itself for --shaders,
// stops an endless shader loop after --timeout with a message, refuses a renamed
// varying naming both files, warns about NaN/Inf pixels and uniforms nothing
// sets, and ignores a UTF-8 byte-order mark.
//
// Every case runs in a kit root of its own (KIT_ROOT): the framework's shaders,
// and lab and "solution" folders holding shaders this file writes, so no real
// solution is needed (a student copy runs these tests).
#include <gtest/gtest.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "images/image_io.h"
#include "kit_test.h"
#include "kit_test_files.h"
#include "kit_test_images.h"
#include "render/stages.h"
#include "base/watchdog.h"

namespace fs = std::filesystem;

namespace {

// The geometry pass, complete enough to fill every G-buffer attachment.
const std::string kGbufferVert = R"(#version 330 core
#include "geometry_uniforms.glsl"

layout(location = KIT_ATTR_POSITION) in vec3 a_position;
layout(location = KIT_ATTR_NORMAL) in vec3 a_normal;

out vec3 v_world_position;
out vec3 v_world_normal;

void main() {
    // The starter's placeholders, not lab 1's answer: these tests need a
    // G-buffer that renders, not a right one (a student copy holds this file).
    v_world_position = vec3(0.0);
    v_world_normal = a_normal;
    gl_Position = u_projection * u_view * u_model * vec4(a_position, 1.0);
}
)";

const std::string kGbufferFrag = R"(#version 330 core
#include "geometry_uniforms.glsl"

in vec3 v_world_position;
in vec3 v_world_normal;

layout(location = KIT_GBUF_POSITION) out vec4 out_position;
layout(location = KIT_GBUF_NORMAL) out vec4 out_normal;
layout(location = KIT_GBUF_ALBEDO) out vec4 out_albedo;
layout(location = KIT_GBUF_MATERIAL) out vec4 out_material;
layout(location = KIT_GBUF_EMISSION) out vec4 out_emission;

void main() {
    vec3 n = normalize(v_world_normal);
    out_position = vec4(v_world_position, 1.0);
    out_normal = vec4(n, 0.0);
    out_albedo = vec4(u_base_color_factor.rgb, 1.0);
    out_material = vec4(u_metallic_factor, u_roughness_factor, 0.0, 1.0);
    out_emission = vec4(u_emissive_factor, 0.0);
}
)";

// Stage 2's lighting pass, reduced to showing the normals: enough to tell stages apart.
const std::string kLightingFrag = R"(#version 330 core
#include "uniforms.glsl"

in vec2 v_uv;
out vec4 out_color;

void main() {
    vec4 material = texture(u_gbuffer_material, v_uv);
    vec3 n = texture(u_gbuffer_normal, v_uv).xyz;
    out_color = vec4(material.a > 0.5 ? 0.5 * n + 0.5 : u_clear_color, 1.0);
}
)";
const std::string kBrdf = "// not used by this lighting pass\n";

const std::string kUtf8Bom = "\xEF\xBB\xBF";

std::string quoted(const std::string& s) { return "'" + s + "'"; }

// `text` with its one occurrence of `from` replaced; fails the test when it is not there.
std::string replaced(std::string text, const std::string& from, const std::string& to) {
  size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << "'" << from << "' is not in the shader";
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

class StudentTools : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    root_ = kit::test::temp_dir(std::string("student_tools/") + info->name());
    fs::copy(kit::shaders_dir(), root_ / "shaders", fs::copy_options::recursive);
    // "Solutions" of lab 1 that differ from the lab's own files (grey albedo), to tell them apart.
    lab("solutions", "01-gbuffer", kGbufferVert,
        replaced(kGbufferFrag, "vec4(u_base_color_factor.rgb, 1.0)", "vec4(0.5, 0.5, 0.5, 1.0)"));
    lab("labs", "01-gbuffer", kGbufferVert, kGbufferFrag);
    kit::test::write_file(root_ / "labs" / "02-lighting" / "lighting.frag", kLightingFrag);
    kit::test::write_file(root_ / "labs" / "02-lighting" / "brdf.glsl", kBrdf);
  }

  void lab(const std::string& top, const std::string& folder, const std::string& vert, const std::string& frag) {
    kit::test::write_file(root_ / top / folder / "gbuffer.vert", vert);
    kit::test::write_file(root_ / top / folder / "gbuffer.frag", frag);
  }

  // kit-render in this test's kit root; its exit status, its stdout and stderr in *output.
  // `environment`: variables set for it alone ("NAME=value ").
  int render(const std::string& args, std::string* output, const std::string& environment = "") {
    std::string command = environment + "KIT_ROOT=" + quoted(root_.string()) + " " +
                          quoted(kit::test::tool("kit-render")) + " " + args;
    return kit::test::run(command, output);
  }

  std::string out(const std::string& name) const { return quoted((root_ / name).string()); }
  kit::Image image(const std::string& name) const { return kit::read_image((root_ / name).string()); }

  fs::path root_;
};

// The endless-loop runs with one llvmpipe rasterizer thread: the loop then spins on one
// core, not on every core, for the seconds the timeout waits. The watchdog is what is
// tested, and it ends the process however many threads spin.
const std::string kOneRasterizerThread = "LP_NUM_THREADS=1 ";

TEST_F(StudentTools, EndlessLoopStopsAfterTheTimeout) {
  // llvmpipe caps a loop at 65535 iterations, so "endless" means far longer than
  // the timeout: 65535 iterations at each of 640x480 pixels take tens of seconds.
  const std::string endless = replaced(kGbufferFrag, "    out_position = vec4(v_world_position, 1.0);\n",
                                       "    float x = 1.0;\n"
                                       "    while (x > 0.0)  // never ends: x only grows\n"
                                       "        while (x > 0.0) x += abs(u_roughness_factor);\n"
                                       "    out_position = vec4(v_world_position, x);\n");
  std::string output;
  ASSERT_EQ(render("--timeout 3 --out " + out("clean.png"), &output, kOneRasterizerThread), 0)
      << "witness, without the loop:\n" << output;

  lab("labs", "01-gbuffer", kGbufferVert, endless);
  auto start = std::chrono::steady_clock::now();
  int status = render("--timeout 3 --out " + out("endless.png"), &output, kOneRasterizerThread);
  double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_EQ(status, kit::kTimedOutStatus) << output;
  EXPECT_TRUE(contains(output, "kit-render: timed out after 3 s rendering stage gbuffer: does a shader loop forever?"))
      << output;
  EXPECT_LT(seconds, 20.0) << "the watchdog should end the run soon after 3 s";
  EXPECT_FALSE(fs::exists(root_ / "endless.png"));
}

TEST_F(StudentTools, LabFolderOrItsParentGiveTheSameImage) {
  std::string output;
  // Stage 2 from the lab folder alone (no --stage) and from the folder of lab folders.
  ASSERT_EQ(render("--shaders " + out("labs/02-lighting") + " --size 160x120 --out " + out("folder.exr"), &output), 0)
      << output;
  ASSERT_EQ(render("--shaders " + out("labs") + " --stage lighting --size 160x120 --out " + out("root.exr"), &output), 0)
      << output;
  ASSERT_EQ(render("--shaders " + out("labs/02-lighting/") + " --size 160x120 --out " + out("slash.exr"), &output), 0)
      << output;
  EXPECT_EQ(kit::test::first_difference(image("folder.exr"), image("root.exr")), "");
  EXPECT_EQ(kit::test::first_difference(image("slash.exr"), image("root.exr")), "");
  // The stage came from the folder: without it, the default stage (gbuffer) gives another image.
  ASSERT_EQ(render("--shaders " + out("labs") + " --size 160x120 --out " + out("stage1.exr"), &output), 0) << output;
  EXPECT_NE(kit::test::first_difference(image("stage1.exr"), image("root.exr")), "");

  // labs/ is the default; --solution takes solutions/ (whose lab 1 here differs).
  ASSERT_EQ(render("--size 160x120 --out " + out("default.exr"), &output), 0) << output;
  EXPECT_EQ(kit::test::first_difference(image("default.exr"), image("stage1.exr")), "");
  ASSERT_EQ(render("--solution --size 160x120 --out " + out("solution.exr"), &output), 0) << output;
  EXPECT_NE(kit::test::first_difference(image("solution.exr"), image("stage1.exr")), "");

  // A lab folder and a --stage that disagree, and --solution with --shaders, are refused.
  EXPECT_NE(render("--shaders " + out("labs/02-lighting") + " --stage attenuation --out " + out("x.png"), &output), 0);
  EXPECT_TRUE(contains(output, "is the folder of lab 2 (lighting), but --stage asks for lab 3 (attenuation)")) << output;
  EXPECT_NE(render("--solution --shaders " + out("labs") + " --out " + out("x.png"), &output), 0);
  EXPECT_TRUE(contains(output, "--solution and --shaders")) << output;
}

TEST_F(StudentTools, MissingLabFolderSaysWhichAndHowToFixIt) {
  std::string output;
  EXPECT_EQ(render("--stage attenuation --out " + out("x.png"), &output), 1);
  EXPECT_TRUE(contains(output, (root_ / "labs" / "03-attenuation").string() + ": no such folder")) << output;
  EXPECT_TRUE(contains(output, "git checkout -- labs/03-attenuation")) << output;
  EXPECT_EQ(render("--solution --stage lighting --out " + out("x.png"), &output), 1);
  EXPECT_TRUE(contains(output, (root_ / "solutions" / "02-lighting").string() + ": no such folder")) << output;
  EXPECT_TRUE(contains(output, "leave out --solution")) << output;
  EXPECT_EQ(render("--shaders " + out("nowhere") + " --out " + out("x.png"), &output), 1);
  EXPECT_TRUE(contains(output, (root_ / "nowhere").string() + ": no such folder")) << output;
}

TEST_F(StudentTools, RenamedVaryingFailsNamingBothFilesAndTheVariable) {
  std::string output;
  ASSERT_EQ(render("--size 64x48 --out " + out("witness.png"), &output), 0) << "witness, names matching:\n" << output;

  std::string vert = replaced(kGbufferVert, "out vec3 v_world_normal;", "out vec3 v_normal_in_world;");
  vert = replaced(vert, "v_world_normal = a_normal", "v_normal_in_world = a_normal");
  lab("labs", "01-gbuffer", vert, kGbufferFrag);
  EXPECT_EQ(render("--size 64x48 --out " + out("renamed.png"), &output), 1) << output;
  EXPECT_TRUE(contains(output, "kit-render: link error (labs/01-gbuffer/gbuffer.vert + labs/01-gbuffer/gbuffer.frag)"))
      << output;
  // The input's own line (line 5 of the fragment shader) and what the vertex shader writes.
  EXPECT_TRUE(contains(output, "labs/01-gbuffer/gbuffer.frag:5: fragment shader input `v_world_normal' has no matching "
                               "output in the vertex shader labs/01-gbuffer/gbuffer.vert"))
      << output;
  EXPECT_TRUE(contains(output, "(it writes: v_world_position, v_normal_in_world)")) << output;
  EXPECT_FALSE(fs::exists(root_ / "renamed.png"));
}

TEST_F(StudentTools, NanPixelsAreCountedPerView) {
  std::string output;
  ASSERT_EQ(render("--size 64x48 --out " + out("clean.png"), &output), 0) << output;
  EXPECT_FALSE(contains(output, "NaN")) << "witness, a clean shader:\n" << output;

  lab("labs", "01-gbuffer", kGbufferVert,
      replaced(kGbufferFrag, "    out_normal = vec4(n, 0.0);",
               "    float zero = u_metallic_factor * 0.0;\n    out_normal = vec4(n * (zero / zero), 0.0);"));
  ASSERT_EQ(render("--size 64x48 --out " + out("nan.png"), &output), 0) << "NaN is a warning, not an error:\n" << output;
  // Every covered pixel's normal is NaN; the other views are clean.
  const std::string prefix = "kit-render: warning: ";
  size_t at = output.find(prefix);
  ASSERT_NE(at, std::string::npos) << output;
  size_t count = std::stoul(output.substr(at + prefix.size()));
  EXPECT_GT(count, 100u) << output;
  EXPECT_TRUE(contains(output, std::to_string(count) + " of 3072 pixels of the normal view are NaN or Inf: guard the "
                               "divisions and square roots (guards.glsl)"))
      << output;
  EXPECT_FALSE(contains(output, "position view")) << output;
  EXPECT_FALSE(contains(output, "material view")) << output;
  EXPECT_FALSE(contains(output, "emission view")) << output;
}

TEST_F(StudentTools, UniformNothingSetsIsAWarningNamingItsLine) {
  std::string output;
  ASSERT_EQ(render("--size 64x48 --out " + out("clean.png"), &output), 0) << output;
  EXPECT_FALSE(contains(output, "uniform")) << "witness, only the framework's uniforms:\n" << output;

  std::string frag = replaced(kGbufferFrag, "void main() {", "uniform float u_exposure;\n\nvoid main() {");
  frag = replaced(frag, "vec4(u_base_color_factor.rgb, 1.0)", "vec4(u_base_color_factor.rgb * u_exposure, 1.0)");
  lab("labs", "01-gbuffer", kGbufferVert, frag);
  ASSERT_EQ(render("--size 64x48 --out " + out("unset.png"), &output), 0) << output;
  EXPECT_TRUE(contains(output, "kit-render: warning: labs/01-gbuffer/gbuffer.frag:13: uniform `u_exposure' is never set "
                               "by the framework"))
      << output;
  EXPECT_TRUE(contains(output, "so it reads 0")) << output;
}

TEST_F(StudentTools, UniformOfAnotherTypeIsAnErrorNamingItsLine) {
  // Uniforms declared by hand instead of through geometry_uniforms.glsl, one with the wrong type.
  const std::string vert = R"(#version 330 core
#include "gbuffer_layout.h"
uniform mat4 u_model;
uniform mat4 u_view;
uniform mat4 u_projection;
layout(location = KIT_ATTR_POSITION) in vec3 a_position;
layout(location = KIT_ATTR_NORMAL) in vec3 a_normal;
out vec3 v_world_normal;
void main() {
    v_world_normal = a_normal;
    gl_Position = u_projection * u_view * u_model * vec4(a_position, 1.0);
}
)";
  const std::string frag = R"(#version 330 core
#include "gbuffer_layout.h"
uniform vec4 u_base_color_factor;
uniform float u_roughness_factor;
in vec3 v_world_normal;
layout(location = KIT_GBUF_POSITION) out vec4 out_position;
layout(location = KIT_GBUF_NORMAL) out vec4 out_normal;
layout(location = KIT_GBUF_ALBEDO) out vec4 out_albedo;
layout(location = KIT_GBUF_MATERIAL) out vec4 out_material;
void main() {
    out_position = vec4(0.0, 0.0, 0.0, 1.0);
    out_normal = vec4(v_world_normal, 0.0);
    out_albedo = u_base_color_factor;
    out_material = vec4(0.0, u_roughness_factor, 0.0, 1.0);
}
)";
  std::string output;
  lab("labs", "01-gbuffer", vert, frag);
  ASSERT_EQ(render("--size 64x48 --out " + out("float.png"), &output), 0) << "witness, declared float:\n" << output;
  lab("labs", "01-gbuffer", vert,
      replaced(replaced(frag, "uniform float u_roughness_factor;", "uniform vec3 u_roughness_factor;"),
               "vec4(0.0, u_roughness_factor, 0.0, 1.0)", "vec4(0.0, u_roughness_factor.x, 0.0, 1.0)"));
  EXPECT_EQ(render("--size 64x48 --out " + out("vec3.png"), &output), 1) << output;
  EXPECT_TRUE(contains(output, "kit-render: labs/01-gbuffer/gbuffer.frag:4: uniform `u_roughness_factor' is declared "
                               "vec3, but the framework sets it as float"))
      << output;
}

// kit-view stops the same way (a stuck frame blocks the window too). Under Xvfb,
// as the window tests run it; the viewer is optional, so is this test.
TEST_F(StudentTools, ViewerEndlessLoopStopsAfterTheTimeout) {
  const std::string viewer = kit::test::tool("kit-view");
  if (!fs::exists(viewer)) GTEST_SKIP() << "kit-view is not built (KIT_BUILD_VIEWER is off)";
  std::string output;
  ASSERT_EQ(kit::test::run("command -v xvfb-run", &output), 0) << "xvfb-run is not installed (Debian: xvfb)";
  // kit-view's own exit status, printed from inside xvfb-run: xvfb-run (Debian package xvfb)
  // can exit 5 instead, "problem while cleaning up temporary directory", after the command
  // has ended (seen once under ctest -j2 in a student copy).
  auto view = [&](std::string* text) {
    kit::test::run(kOneRasterizerThread + "KIT_ROOT=" + quoted(root_.string()) +
                       " xvfb-run -a -s '-screen 0 1024x768x24' sh -c '\"$0\" \"$@\"; echo \"kit-view exit status $?\"' " +
                       quoted(viewer) + " --frames 2 --timeout 3",
                   text);
    const std::string marker = "kit-view exit status ";
    const size_t at = text->rfind(marker);
    return at == std::string::npos ? -1 : std::atoi(text->c_str() + at + marker.size());
  };
  ASSERT_EQ(view(&output), 0) << "witness, without the loop:\n" << output;
  lab("labs", "01-gbuffer", kGbufferVert,
      replaced(kGbufferFrag, "    out_position = vec4(v_world_position, 1.0);\n",
               "    float x = 1.0;\n    while (x > 0.0)\n        while (x > 0.0) x += abs(u_roughness_factor);\n"
               "    out_position = vec4(v_world_position, x);\n"));
  EXPECT_EQ(view(&output), kit::kTimedOutStatus) << output;
  EXPECT_TRUE(contains(output, "kit-view: timed out after 3 s rendering stage gbuffer: does a shader loop forever?"))
      << output;
}

TEST_F(StudentTools, ByteOrderMarkIsIgnored) {
  std::string output;
  const std::string views = " --size 160x120 --view normal --out ";
  ASSERT_EQ(render(views + out("plain-normal.exr") + " --view albedo --out " + out("plain-albedo.png"), &output), 0)
      << output;
  lab("labs", "01-gbuffer", kUtf8Bom + kGbufferVert, kUtf8Bom + kGbufferFrag);
  ASSERT_EQ(render(views + out("bom-normal.exr") + " --view albedo --out " + out("bom-albedo.png"), &output), 0)
      << output;
  EXPECT_FALSE(contains(output, "#version 330 core")) << "no first-line complaint:\n" << output;
  EXPECT_EQ(kit::test::first_difference(image("bom-normal.exr"), image("plain-normal.exr")), "");
  EXPECT_EQ(kit::test::first_difference(image("bom-albedo.png"), image("plain-albedo.png")), "");
}

}  // namespace
