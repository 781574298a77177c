// kit-grade's render worker (tools/grade/worker/) on broken labs: compile and link errors,
// NaN in a frame or in a precomputed map, a shader that writes nothing, an endless loop.
// Each lab scores zero with a message that names what broke, and the others keep full
// marks; and the solutions get full marks on EGL too.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "grade_runs.h"
#include "kit_test.h"
#include "kit_test_files.h"
#include "render/stages.h"

namespace fs = std::filesystem;
using namespace kit::test;  // the helpers of support/ included above

namespace {

// Short wall-clock limit for the run holding the endless loop.
constexpr int kShortTimeoutSeconds = 5;

}  // namespace

TEST(Grader, SolutionsScoreFullMarksOnEgl) {
  GradeRun r = grade(kit::kit_root() / "solutions", "solutions-egl", "--backend egl");
  expect_ran(r);
  for (int n = 1; n <= kLabCount; ++n) expect_full_marks(r, n);
  EXPECT_NE(r.summary["renderer"].get<std::string>().find("egl"), std::string::npos) << r.summary["renderer"];
}

// Run A: a syntax error, NaN everywhere, a link error and an endless loop, with the
// solution in lab 3, which keeps full marks. The endless loop (lab 5) is graded in a
// run of its own under the short timeout; labs 1-4 keep the default one, so a busy
// machine (the suite runs two tests at once, ASan slows rendering several times)
// cannot push lab 3 past the short limit.
TEST(Grader, BrokenLabsScoreZeroAndTheOthersFullMarksA) {
  fs::path sub = kit::test::temp_dir("grader-bad-a");
  for (int n = 1; n <= kLabCount; ++n) copy_lab("solutions", n, sub);
  // Line 12 of gbuffer.frag becomes a syntax error.
  std::string frag = read_file(sub / "01-gbuffer/gbuffer.frag");
  size_t line12 = 0;
  for (int i = 1; i < 12; ++i) line12 = frag.find('\n', line12) + 1;
  write_file(sub / "01-gbuffer/gbuffer.frag", frag.insert(line12, "this is not GLSL;\n"));
  edit(sub / "02-lighting/lighting.frag", "out_color = vec4(min(radiance, vec3(KIT_HDR_MAX)), 1.0);",
       "float zero = material.a * 0.0;\n    out_color = vec4(vec3(zero / zero), 1.0);");
  edit(sub / "02-lighting/lighting.frag", "out_color = vec4(u_clear_color, 1.0);\n        return;",
       "float zero = material.a * 0.0;\n        out_color = vec4(vec3(zero / zero), 1.0);\n        return;");
  // The vertex stage's output and the fragment stage's input disagree (Mesa refuses
  // a type mismatch at link time; a renamed output is the next test's case).
  edit(sub / "04-normalmap/gbuffer.vert", "out vec3 v_world_tangent;", "out vec4 v_world_tangent;");
  edit(sub / "04-normalmap/gbuffer.vert", "v_world_tangent = t;", "v_world_tangent = vec4(t, 0.0);");
  edit(sub / "05-postprocess/blur.frag", "void main() {",
       "void main() {\n    float x = 1.0;\n    while (x > 0.0) x += u_resolution.x;  // never ends\n    if (x < 0.0) discard;");
  GradeRun r = grade(sub, "bad-a", "--labs 1-4");
  expect_ran(r);
  expect_zero(r, 1, "compile_error", "labs/01-gbuffer/gbuffer.frag:12");
  expect_zero(r, 2, "graded", "NaN or Inf");
  expect_full_marks(r, 3);
  expect_zero(r, 4, "compile_error", "link error (labs/04-normalmap/gbuffer.vert + labs/04-normalmap/gbuffer.frag)");
  expect_zero(r, 4, "compile_error", "v_world_tangent");
  // One llvmpipe rasterizer thread: the loop spins on one core, not on every core, until
  // the timeout (which is what is tested, however many threads spin).
  GradeRun endless =
      grade(sub, "bad-a-endless", "--labs 5 --timeout " + std::to_string(kShortTimeoutSeconds), "LP_NUM_THREADS=1 ");
  expect_ran(endless);
  expect_zero(endless, 5, "timeout", "did not finish within 5 s");
  std::string report = read_file(r.out / "report.html");
  EXPECT_NE(report.find("<pre>"), std::string::npos);
  EXPECT_NE(report.find("labs/01-gbuffer/gbuffer.frag:12"), std::string::npos);
}

// A vertex output renamed so no fragment input matches it: Mesa links that (the
// input reads zero) but other drivers do not, so the grader reports a link error.
TEST(Grader, UnmatchedVaryingNamesAreALinkError) {
  fs::path sub = kit::test::temp_dir("grader-varying");
  copy_lab("solutions", 1, sub);
  edit(sub / "01-gbuffer/gbuffer.vert", "out vec3 v_world_normal;", "out vec3 v_normal_in_world;");
  edit(sub / "01-gbuffer/gbuffer.vert", "v_world_normal = u_normal_matrix * a_normal;",
       "v_normal_in_world = u_normal_matrix * a_normal;");
  GradeRun r = grade(sub, "varying", "--labs 1");
  expect_ran(r);
  expect_zero(r, 1, "compile_error", "link error (labs/01-gbuffer/gbuffer.vert + labs/01-gbuffer/gbuffer.frag)");
  expect_zero(r, 1, "compile_error", "input `v_world_normal' has no matching output");
  EXPECT_EQ(r.summary["labs"].size(), 1u) << "only the lab asked for";
}

// Run B: a shader that writes nothing, an #include outside the allowed folders,
// binary garbage and a wrong #version, with the solution in lab 4.
TEST(Grader, BrokenLabsScoreZeroAndTheOthersFullMarksB) {
  fs::path sub = kit::test::temp_dir("grader-bad-b");
  for (int n = 1; n <= kLabCount; ++n) copy_lab("solutions", n, sub);
  edit(sub / "01-gbuffer/gbuffer.frag", "void main() {", "void main() {\n    discard;");
  edit(sub / "02-lighting/brdf.glsl", "#include \"math.glsl\"", "#include \"../../../etc/passwd\"");
  write_file(sub / "03-attenuation/attenuation.glsl", std::string("\x7f" "ELF\x02\x01\x01\0\0\0garbage\xff\xfe", 20));
  edit(sub / "05-postprocess/bright.frag", "#version 330 core", "#version 450 core");
  GradeRun r = grade(sub, "bad-b");
  expect_ran(r);
  expect_zero(r, 1, "graded", "does the shader write its output?");
  expect_zero(r, 2, "compile_error", "refused");
  expect_zero(r, 3, "invalid_files", "binary data");
  expect_full_marks(r, 4);
  expect_zero(r, 5, "compile_error", "labs/05-postprocess/bright.frag:1");
}

// A lab 6 shader that writes NaN into a precomputed map (the BRDF table without its n.v
// guards: 0/0 in its first column). The frame would hide it (ibl.h, IblSettings::
// refuse_non_finite), so the lab is not graded, with a status of its own and a message
// naming the file, the map and the texel.
TEST(Grader, NanInAPrecomputedMapIsNamed) {
  fs::path sub = kit::test::temp_dir("grader-nan-map");
  copy_lab("solutions", 6, sub);
  edit(sub / "06-ibl/brdf_lut.frag", "float n_dot_v = max(kit_brdf_lut_grid_value(v_uv.x), KIT_MIN_N_DOT_V);",
       "float n_dot_v = kit_brdf_lut_grid_value(v_uv.x);");
  edit(sub / "06-ibl/brdf_lut.frag", "float weight = g * v_dot_h / max(n_dot_h * n_dot_v, KIT_MIN_DENOMINATOR);",
       "float weight = g * v_dot_h / (n_dot_h * n_dot_v);");
  GradeRun r = grade(sub, "nan-map", "--labs 6");
  expect_ran(r);
  expect_zero(r, 6, "non_finite_map", "labs/06-ibl/brdf_lut.frag wrote NaN into the BRDF table, texel (0, ");
  EXPECT_NE(read_file(r.out / "report.html").find("NaN or Inf in a precomputed map"), std::string::npos);
}
