// kit-grade end to end: the binary is run on submissions built here in temp
// folders from copies of solutions/ and labs/ (big and binary files are made
// at test time). Each kit-grade run is shared by many assertions, and several
// broken labs that do not interact sit in one submission, so the suite stays
// well under two minutes.
#include <OpenImageIO/imagebufalgo.h>
#include <cmath>
#include <csignal>
#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <functional>
#include <map>
#include <set>
#include <utility>
#include <vector>

#include "files/files.h"
#include "frames/checks.h"
#include "gbuffer_layout.h"  // KIT_LIGHT_*
#include "images/image_io.h"
#include "kit_test.h"
#include "reference_store/references.h"
#include "render/stages.h"
#include "report/report.h"
#include "run/grader.h"
#include "run/grading_run.h"
#include "run/scheduler.h"
#include "verdict/compare.h"
#include "verdict/config.h"
#include "verdict/lab_verdict.h"

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

// Every lab of the stage table (common/render/stages.cpp) is graded.
const int kLabCount = static_cast<int>(kit::stages().size());
// Short wall-clock limit for the run holding the endless loop.
constexpr int kShortTimeoutSeconds = 5;

struct GradeRun {
  int exit_code = -1;
  std::string output;
  json results, summary;
  fs::path out;
};

std::string quoted(const fs::path& p) { return "'" + p.string() + "'"; }

json read_json(const fs::path& path) {
  std::ifstream in(path);
  if (!in) return json();
  try {
    return json::parse(in);
  } catch (const json::exception&) {
    return json("not valid JSON");
  }
}

// Runs kit-grade (two labs at a time unless `extra` says otherwise).
// `environment`: variables set for kit-grade alone ("NAME=value ").
GradeRun grade(const fs::path& submission, const std::string& name, const std::string& extra = "",
               const std::string& environment = "") {
  GradeRun r;
  r.out = kit::test::temp_dir("grader-out-" + name);
  r.exit_code = kit::test::run(environment + kit::test::tool("kit-grade") + " " + quoted(submission) + " --out " + quoted(r.out) +
                                   " --jobs 2 " + extra,
                               &r.output);
  r.results = read_json(r.out / "results.json");
  r.summary = read_json(r.out / "summary.json");
  return r;
}

// Copies a lab folder (NN-name) of solutions/ or labs/ into `root`.
void copy_lab(const std::string& from, int lab, const fs::path& root) {
  const std::string folder = kit::find_stage(lab).folder;
  fs::create_directories(root / folder);
  fs::copy(kit::kit_root() / from / folder, root / folder,
           fs::copy_options::recursive | fs::copy_options::overwrite_existing);
}

void write_file(const fs::path& path, const std::string& text) {
  fs::create_directories(path.parent_path());
  std::ofstream out(path, std::ios::binary);
  out << text;
}

std::string read_file(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

// Replaces the only occurrence of `find` in a file (fails the test when it is not there once).
void edit(const fs::path& path, const std::string& find, const std::string& replace) {
  std::string text = read_file(path);
  size_t at = text.find(find);
  ASSERT_NE(at, std::string::npos) << path << " has no '" << find << "'";
  ASSERT_EQ(text.find(find, at + 1), std::string::npos) << path << " has '" << find << "' twice";
  write_file(path, text.replace(at, find.size(), replace));
}

// Gradescope's results.json: the keys and types its autograder reads.
void expect_gradescope_schema(const json& r) {
  ASSERT_TRUE(r.is_object()) << r.dump();
  EXPECT_TRUE(r["score"].is_number());
  EXPECT_TRUE(r["execution_time"].is_number());
  EXPECT_TRUE(r["output"].is_string());
  ASSERT_TRUE(r["tests"].is_array());
  EXPECT_FALSE(r["tests"].empty());
  long long sum = 0, max_sum = 0;  // thousandths: scores are exact thousandths of a point
  for (const json& t : r["tests"]) {
    ASSERT_TRUE(t.is_object());
    EXPECT_TRUE(t["name"].is_string());
    EXPECT_TRUE(t["score"].is_number());
    EXPECT_TRUE(t["max_score"].is_number());
    EXPECT_TRUE(t["status"] == "passed" || t["status"] == "failed") << t.dump();
    EXPECT_TRUE(t["output"].is_string());
    EXPECT_EQ(t["output_format"], "md");
    EXPECT_EQ(t["visibility"], "visible");
    EXPECT_LE(t["score"].get<double>(), t["max_score"].get<double>() + 1e-9);
    sum += std::llround(t["score"].get<double>() * 1000.0);
    max_sum += std::llround(t["max_score"].get<double>() * 1000.0);
  }
  // Shares are apportioned in thousandths (Config::max_score), so the sums are exact:
  // 7 checks of a 10-point lab add up to 10, not 10.003 (nor 9.999999999999998).
  EXPECT_EQ(sum, std::llround(r["score"].get<double>() * 1000.0)) << "the tests' scores add up to the total";
  EXPECT_EQ(max_sum % 10000, 0) << "grading.json's labs are worth 10 points each: " << max_sum;
  ASSERT_TRUE(r["leaderboard"].is_array());
  ASSERT_EQ(r["leaderboard"].size(), 1u);
  EXPECT_EQ(r["leaderboard"][0]["name"], "render time (ms)");
  EXPECT_TRUE(r["leaderboard"][0]["value"].is_number());
  EXPECT_EQ(r["leaderboard"][0]["order"], "asc");
}

const json& lab(const GradeRun& r, int number) { return r.summary["labs"][std::to_string(number)]; }

// All tests of one lab in results.json, joined (to look for a message).
std::string lab_outputs(const GradeRun& r, int number) {
  std::string prefix = "lab " + std::to_string(number) + " ", text;
  for (const json& t : r.results["tests"])
    if (t["name"].get<std::string>().rfind(prefix, 0) == 0) text += t["output"].get<std::string>() + "\n";
  return text;
}

void expect_full_marks(const GradeRun& r, int number) {
  const json& l = lab(r, number);
  EXPECT_EQ(l["status"], "graded") << "lab " << number << ": " << l.dump();
  EXPECT_GT(l["max_score"].get<double>(), 0.0);
  EXPECT_DOUBLE_EQ(l["score"].get<double>(), l["max_score"].get<double>()) << "lab " << number << ": " << l.dump(1);
}

void expect_zero(const GradeRun& r, int number, const std::string& status, const std::string& message_part) {
  const json& l = lab(r, number);
  EXPECT_EQ(l["status"], status) << "lab " << number << ": " << l.dump(1);
  EXPECT_DOUBLE_EQ(l["score"].get<double>(), 0.0) << "lab " << number;
  std::string message = l["message"].get<std::string>() + "\n" + lab_outputs(r, number);
  EXPECT_NE(message.find(message_part), std::string::npos)
      << "lab " << number << ": the message should say '" << message_part << "':\n" << message;
}

void expect_ran(const GradeRun& r) {
  EXPECT_EQ(r.exit_code, 0) << r.output;
  expect_gradescope_schema(r.results);
  EXPECT_TRUE(fs::exists(r.out / "report.html"));
}

// Zips `entries` (name in the archive -> content) into `zip` with Python's zipfile,
// which writes any name, "../" included.
void make_zip(const fs::path& zip, const std::map<std::string, std::string>& entries) {
  fs::path spec = zip;
  spec += ".json";
  write_file(spec, json(entries).dump());
  std::string script = "import json,sys,zipfile\n"
                       "z=zipfile.ZipFile(sys.argv[2],'w')\n"
                       "[z.writestr(n,c) for n,c in json.load(open(sys.argv[1])).items()]\n"
                       "z.close()\n";
  write_file(zip.parent_path() / "make_zip.py", script);
  std::string output;
  ASSERT_EQ(kit::test::run("python3 " + quoted(zip.parent_path() / "make_zip.py") + " " + quoted(spec) + " " + quoted(zip), &output), 0)
      << output;
}

std::map<std::string, std::string> solution_entries(const std::string& prefix) {
  std::map<std::string, std::string> entries;
  for (const kit::Stage& s : kit::stages())
    for (const std::string& f : s.files)
      entries[prefix + s.folder + "/" + f] = read_file(kit::kit_root() / "solutions" / s.folder / f);
  return entries;
}

}  // namespace

// The solutions get full marks, three runs in a row, as a folder, as a zip with a
// labs/ wrapper and inside a student-named wrapper folder.
TEST(Grader, SolutionsScoreFullMarksThreeRunsOnOsmesa) {
  fs::path dir = kit::test::temp_dir("grader-solutions");
  fs::path wrapped = dir / "alice";
  for (int n = 1; n <= kLabCount; ++n) copy_lab("solutions", n, wrapped / "labs-of-alice");
  make_zip(dir / "bob.zip", solution_entries("labs/"));
  const fs::path submissions[] = {kit::kit_root() / "solutions", dir / "bob.zip", wrapped};
  // The summary line counts lab 2's checks as grading.json lists them, and the total its weights.
  std::ifstream config(kit::kit_root() / "tools" / "grade" / "grading.json");
  const json labs = json::parse(config)["labs"];
  const std::string lab2_checks = std::to_string(labs["2"]["checks"].size());
  double weights = 0.0;
  for (const auto& [number, lab] : labs.items()) weights += lab["weight"].get<double>();
  const std::string total = std::to_string(static_cast<int>(weights));
  int run = 0;
  for (const fs::path& submission : submissions) {
    GradeRun r = grade(submission, "solutions-" + std::to_string(++run));
    expect_ran(r);
    for (int n = 1; n <= kLabCount; ++n) expect_full_marks(r, n);
    EXPECT_DOUBLE_EQ(r.summary["total"].get<double>(), r.summary["max_total"].get<double>());
    for (const json& t : r.results["tests"]) EXPECT_EQ(t["status"], "passed") << t["name"];
    EXPECT_NE(r.output.find("lab 2 lighting: 10/10  (" + lab2_checks + " of " + lab2_checks + " checks passed)"),
              std::string::npos)
        << r.output;
    EXPECT_NE(r.output.find("total: " + total + "/" + total), std::string::npos) << r.output;
  }
}

TEST(Grader, SolutionsScoreFullMarksOnEgl) {
  GradeRun r = grade(kit::kit_root() / "solutions", "solutions-egl", "--backend egl");
  expect_ran(r);
  for (int n = 1; n <= kLabCount; ++n) expect_full_marks(r, n);
  EXPECT_NE(r.summary["renderer"].get<std::string>().find("egl"), std::string::npos) << r.summary["renderer"];
}

// Lab 5 in a kit without lab 5's solution (a student copy for lab 5, a Classroom 50
// bundle): the custom effect cannot be isolated on the reference bloom, so it is graded
// on the submission's own, and the notes say so. A correct lab keeps full marks there
// (before, every check was a compile error: "bright.frag" not found); a bloom mistake
// costs more there than with the kit's solution, which the note tells the student.
TEST(Grader, Lab5GradesInAKitWithoutItsSolution) {
  const fs::path root = kit::test::temp_dir("grader-kit-without-lab5");
  fs::copy(kit::shaders_dir(), root / "shaders", fs::copy_options::recursive);
  for (int n = 1; n < 5; ++n) copy_lab("solutions", n, root / "solutions");
  const std::string tables = "--labs 5 --references " + quoted(kit::kit_root() / "tools" / "grade" / "references") +
                             " --config " + quoted(kit::kit_root() / "tools" / "grade" / "grading.json");
  const fs::path correct = kit::test::temp_dir("grader-lab5-correct"), wrong = kit::test::temp_dir("grader-lab5-bloom");
  copy_lab("solutions", 5, correct);
  copy_lab("solutions", 5, wrong);
  const std::string folder = kit::find_stage(5).folder;
  fs::copy_file(kit::kit_root() / "labs" / folder / "bright.frag", wrong / folder / "bright.frag",
                fs::copy_options::overwrite_existing);
  auto own_bloom_noted = [](const GradeRun& r) {
    for (const auto& note : r.summary["notes"])
      if (note.get<std::string>().find("graded on your own bloom") != std::string::npos) return true;
    return false;
  };

  GradeRun stripped = grade(correct, "lab5-stripped", tables, "KIT_ROOT=" + quoted(root) + " ");
  expect_ran(stripped);
  expect_full_marks(stripped, 5);
  EXPECT_TRUE(own_bloom_noted(stripped)) << stripped.summary["notes"];
  GradeRun full = grade(correct, "lab5-full", tables);
  expect_full_marks(full, 5);
  EXPECT_FALSE(own_bloom_noted(full)) << full.summary["notes"];

  GradeRun wrong_stripped = grade(wrong, "lab5-bloom-stripped", tables, "KIT_ROOT=" + quoted(root) + " ");
  GradeRun wrong_full = grade(wrong, "lab5-bloom-full", tables);
  EXPECT_LT(lab(wrong_stripped, 5)["score"].get<double>(), lab(wrong_full, 5)["score"].get<double>());
  EXPECT_LT(lab(wrong_full, 5)["score"].get<double>(), lab(full, 5)["max_score"].get<double>());
}

// The starters (labs/) pass only the checks handouts/instructors.md lists as
// their documented minimum: what the starter code already does right.
TEST(Grader, StartersScoreTheDocumentedMinimum) {
  GradeRun r = grade(kit::kit_root() / "labs", "starters");
  expect_ran(r);
  const std::map<int, std::set<std::string>> documented = {
      {1, {}}, {2, {}}, {3, {}}, {4, {"default-final"}},
      {5, {"default-off", "custom-off", "custom-on-postprocess-off"}}, {6, {}}, {7, {}}};
  for (const auto& [number, passing] : documented) {
    EXPECT_EQ(lab(r, number)["status"], "graded");
    for (const auto& [key, check] : lab(r, number)["checks"].items())
      EXPECT_EQ(check["passed"].get<bool>(), passing.count(key) == 1) << "lab " << number << " check " << key;
  }
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

// A failed lab names the catalogued mistake its checks' signatures resemble
// (tools/grade/verdict/diagnosis.h): here a catalogued one, so its own signatures are in
// mistakes.json. Witness: against the same references without mistakes.json nothing is
// named; the solution, which fails nothing, names nothing either.
TEST(Grader, FailedLabNamesTheLikelyMistake) {
  const fs::path sub = kit::test::temp_dir("grader-named-mistake");
  copy_lab("solutions", 7, sub);
  edit(sub / "07-lightvolumes/light_volume.vert", "cull(front) depth(greater_equal) blend(add)",
       "cull(back) depth(less_equal) blend(add)");
  GradeRun r = grade(sub, "named-mistake", "--labs 7");
  expect_ran(r);
  const json likely = lab(r, 7)["likely_mistakes"];
  ASSERT_FALSE(likely.empty()) << lab(r, 7).dump();
  EXPECT_EQ(likely[0]["id"], "lightvolumes-front-faces-drawn");
  EXPECT_GT(likely[0]["similarity"].get<double>(), 0.99);
  bool said = false;
  for (const json& t : r.results["tests"])
    if (t["status"] == "failed")
      said = said || t["output"].get<std::string>().find("Looks like: back faces culled") != std::string::npos;
  EXPECT_TRUE(said) << r.results.dump();
  EXPECT_NE(read_file(r.out / "report.html").find("handouts/07-lightvolumes.md#common-mistakes"), std::string::npos);
  // The failed checks' worst pixels say what the lighting read there, also on scenes whose
  // G-buffer is kept for that alone (checks.h, describes_pixels_only), with each light's range.
  for (const auto& [key, light] : {std::pair<const char*, const char*>{"inside-hdr", "light 1 (point, range 4 m): towards it"},
                                   {"unranged-hdr", "light 1 (point, no range): towards it"}}) {
    const std::string worst = lab(r, 7)["checks"][key].value("worst_pixel", std::string());
    EXPECT_NE(worst.find("there the G-buffer holds position"), std::string::npos) << key << ": " << worst;
    EXPECT_NE(worst.find(light), std::string::npos) << key << ": " << worst;
    // And what each light gives there in the reference (light_shares.h).
    EXPECT_TRUE(worst.find("the lights give it luminance") != std::string::npos ||
                worst.find("no light reaches it in the reference") != std::string::npos)
        << key << ": " << worst;
  }
  // The frame's evidence, light by light (VolumeEvidence): the light around the camera gets no
  // fragment from front faces, and its volume itself is right.
  const std::string note = lab(r, 7)["checks"]["inside-hdr"].value("note", std::string());
  EXPECT_NE(note.find("light 1 has "), std::string::npos) << note;
  EXPECT_NE(note.find("let 0 fragments reach them"), std::string::npos) << note;
  EXPECT_EQ(note.find("volume, drawn alone"), std::string::npos) << note;

  const fs::path references = kit::test::temp_dir("grader-no-signatures");
  fs::copy(kit::kit_root() / "tools/grade/references", references, fs::copy_options::recursive);
  fs::remove(references / "mistakes.json");
  GradeRun without = grade(sub, "named-mistake-without", "--labs 7 --references " + quoted(references));
  expect_ran(without);
  EXPECT_LT(lab(without, 7)["score"].get<double>(), 10.0);
  EXPECT_TRUE(lab(without, 7)["likely_mistakes"].empty());
  EXPECT_EQ(read_file(without.out / "report.html").find("Looks like"), std::string::npos);

  GradeRun correct = grade(kit::kit_root() / "solutions", "named-mistake-solution", "--labs 7");
  expect_full_marks(correct, 7);
  EXPECT_TRUE(lab(correct, 7)["likely_mistakes"].empty());
  EXPECT_EQ(read_file(correct.out / "report.html").find("catalogued mistake"), std::string::npos);
}

// A run reads a lab's references only once one of its children has rendered (so the
// first children start at once). A reference it cannot read then is the grader's problem
// for that lab alone: status "error", exit status 2, the file named, the other lab graded.
TEST(Grader, UnreadableReferenceIsAGraderErrorOfItsLabAlone) {
  const fs::path references = kit::test::temp_dir("grader-bad-reference");
  fs::copy(kit::kit_root() / "tools/grade/references", references, fs::copy_options::recursive);
  write_file(references / "lab2-default-final.png", "not a PNG");
  GradeRun r = grade(kit::kit_root() / "solutions", "bad-reference", "--labs 1,2 --references " + quoted(references));
  EXPECT_EQ(r.exit_code, 2) << r.output;
  expect_full_marks(r, 1);
  expect_zero(r, 2, "error", "could not read this lab's references: ");
  expect_zero(r, 2, "error", "lab2-default-final.png");
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

// Checks that read other views of one frame (the same scene and settings) share it: lab 1's
// fifteen G-buffer checks read four frames (one a scene), lab 4's eight checks four, and every
// check still gets full marks against references that were rendered one by one.
TEST(Grader, ChecksOfOneFrameReadIt) {
  GradeRun r = grade(kit::kit_root() / "solutions", "one-frame", "--labs 1,4 --keep-temp");
  expect_ran(r);
  expect_full_marks(r, 1);
  expect_full_marks(r, 4);
  const std::string marker = "temporary files kept in ";
  const size_t at = r.output.find(marker);
  ASSERT_NE(at, std::string::npos) << r.output;
  fs::path kept = r.output.substr(at + marker.size());
  kept = kept.string().substr(0, kept.string().find('\n'));
  fs::path submission;
  for (const auto& entry : fs::directory_iterator(kept))
    if (entry.path().filename().string().rfind("submission-", 0) == 0) submission = entry.path();
  ASSERT_FALSE(submission.empty()) << kept;
  const json lab1 = read_json(submission / "lab1" / "child.json");
  const json lab4 = read_json(submission / "lab4" / "child.json");
  EXPECT_EQ(lab1["seconds"]["render_each"].size(), 4u) << lab1.dump();
  EXPECT_EQ(lab4["seconds"]["render_each"].size(), 4u) << lab4.dump();
  // Each render names the Renderer (scene) whose setup time it belongs to (measure.sh).
  EXPECT_EQ(lab1["seconds"]["compile_each"].size(), 4u) << lab1.dump();
  for (const auto& [render, seconds] : lab1["seconds"]["render_each"].items())
    EXPECT_TRUE(lab1["seconds"]["compile_each"].contains(lab1["renderer_of"].value(render, std::string())))
        << render << ": " << lab1.dump();
  // Its four Renderers build the display and debug programs once (LinkedProgramCache).
  EXPECT_GE(lab4.value("programs_reused", 0), 6) << lab4.dump();
  // A later run removes the folders of runs that died, not what --keep-temp kept.
  const fs::path empty = kit::test::temp_dir("grader-empty-submission");
  GradeRun later = grade(empty, "after-keep", "--labs 1");
  EXPECT_TRUE(fs::is_directory(submission / "lab1")) << "removed by a later run as stale: " << later.output;
  fs::remove_all(kept);
}

// A report's images may be links to PNGs in the reference cache (write_report_images): a
// render equal to its reference, a difference image of one colour. Grading another
// submission into the same folder writes new files, never through those links. The
// witness: the first run linked them (one file, two names); the second, whose lab 2 lights
// at half strength, wrote its own renders there, and every cached file kept its bytes.
TEST(Grader, ReportLinksLeaveTheCacheAsItWas) {
  const fs::path cache = kit::test::temp_dir("grader-link-cache");
  const std::string environment = "XDG_CACHE_HOME=" + quoted(cache) + " ";
  const fs::path out = kit::test::temp_dir("grader-link-out");
  auto grade_into_out = [&](const fs::path& submission) {
    std::string output;
    EXPECT_EQ(kit::test::run(environment + kit::test::tool("kit-grade") + " " + quoted(submission) + " --labs 2 --out " +
                                 quoted(out) + " --jobs 2",
                             &output),
              0)
        << output;
  };
  auto linked_renders = [&] {
    int linked = 0;
    for (const auto& entry : fs::directory_iterator(out / "img")) {
      const std::string name = entry.path().filename().string();
      const std::string suffix = ".ref.png";
      if (name.size() <= suffix.size() || name.compare(name.size() - suffix.size(), suffix.size(), suffix) != 0) continue;
      const fs::path render = out / "img" / (name.substr(0, name.size() - suffix.size()) + ".png");
      linked += fs::equivalent(entry.path(), render);
    }
    return linked;
  };
  auto cached_files = [&] {
    std::map<std::string, std::string> bytes;
    for (const auto& entry : fs::recursive_directory_iterator(cache))
      if (entry.is_regular_file() && entry.path().extension() == ".png") bytes[entry.path().string()] = read_file(entry.path());
    return bytes;
  };
  grade_into_out(kit::kit_root() / "solutions");
  EXPECT_GT(linked_renders(), 0) << "no render was linked to its reference's PNG";
  const auto before = cached_files();
  ASSERT_FALSE(before.empty());
  const fs::path dim = kit::test::temp_dir("grader-link-dim");
  copy_lab("solutions", 2, dim);
  edit(dim / "02-lighting/lighting.frag", "out_color = vec4(min(radiance, vec3(KIT_HDR_MAX)), 1.0);",
       "out_color = vec4(min(0.5 * radiance, vec3(KIT_HDR_MAX)), 1.0);");
  grade_into_out(dim);
  EXPECT_EQ(linked_renders(), 0) << "a dimmed render still shows as the reference";
  const auto after = cached_files();
  for (const auto& [path, content] : before) {
    ASSERT_TRUE(after.count(path)) << path;
    EXPECT_TRUE(after.at(path) == content) << path << " changed";
  }
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

// Run C: a symlink out of the submission, an empty file, text that is not UTF-8,
// a 10 MB file and missing files.
TEST(Grader, RefusedAndMissingFilesScoreZero) {
  fs::path dir = kit::test::temp_dir("grader-bad-c");
  fs::path sub = dir / "submission";
  for (int n = 1; n <= kLabCount; ++n) copy_lab("solutions", n, sub);
  write_file(dir / "outside.frag", read_file(sub / "01-gbuffer/gbuffer.frag"));
  fs::remove(sub / "01-gbuffer/gbuffer.frag");
  fs::create_symlink(dir / "outside.frag", sub / "01-gbuffer/gbuffer.frag");
  write_file(sub / "02-lighting/brdf.glsl", "");
  write_file(sub / "03-attenuation/tonemap.glsl", "// caf\xe9 in Latin-1\nvec3 tonemap(vec3 c) { return c; }\n");
  write_file(sub / "04-normalmap/gbuffer.vert", std::string(10 * 1024 * 1024, 'x'));
  fs::remove(sub / "05-postprocess/custom_effect.frag");
  fs::remove(sub / "06-ibl/prefilter.frag");
  GradeRun r = grade(sub, "bad-c");
  expect_ran(r);
  expect_zero(r, 1, "invalid_files", "symbolic link");
  expect_zero(r, 2, "invalid_files", "empty");
  expect_zero(r, 3, "invalid_files", "not UTF-8");
  expect_zero(r, 4, "invalid_files", "over the 262144-byte limit");
  expect_zero(r, 5, "missing_files", "labs/05-postprocess/custom_effect.frag");
  expect_zero(r, 6, "missing_files", "labs/06-ibl/prefilter.frag");
}

TEST(Grader, EmptySubmissionScoresZeroWithValidResults) {
  GradeRun r = grade(kit::test::temp_dir("grader-empty"), "empty");
  expect_ran(r);
  for (int n = 1; n <= kLabCount; ++n) expect_zero(r, n, "missing_files", "missing");
  EXPECT_DOUBLE_EQ(r.results["score"].get<double>(), 0.0);
  // A file name that is not UTF-8 is listed in the notes: the JSON stays valid.
  fs::path odd = kit::test::temp_dir("grader-odd-name");
  write_file(odd / "caf\xe9 \xff.glsl", "x");
  GradeRun o = grade(odd, "odd-name", "--labs 1");
  expect_ran(o);
  EXPECT_NE(o.results["output"].get<std::string>().find("caf\xef\xbf\xbd"), std::string::npos) << o.results["output"];
}

// Zip-slip: an entry with "../" refuses the whole archive before anything is extracted.
TEST(Grader, ZipWithParentEntriesIsRefused) {
  fs::path dir = kit::test::temp_dir("grader-zip-slip");
  auto entries = solution_entries("labs/");
  entries["labs/../../escaped.frag"] = "#version 330 core\nvoid main() {}\n";
  make_zip(dir / "inner" / "slip.zip", entries);
  GradeRun r = grade(dir / "inner" / "slip.zip", "zip-slip");
  expect_ran(r);
  for (int n = 1; n <= kLabCount; ++n) expect_zero(r, n, "invalid_files", "'..'");
  EXPECT_NE(r.results["output"].get<std::string>().find("refused"), std::string::npos);
  EXPECT_FALSE(fs::exists(dir / "escaped.frag"));
  EXPECT_FALSE(fs::exists(dir / "inner" / "escaped.frag"));
  // A top folder named like an unzip option ("-d DIR" would extract elsewhere) is refused too.
  make_zip(dir / "dash.zip", solution_entries("-d/"));
  GradeRun d = grade(dir / "dash.zip", "zip-dash", "--labs 2");
  expect_ran(d);
  expect_zero(d, 2, "invalid_files", "starts with '-'");
}

// Lab 5's pass probes in the class summary: each pass counted apart by its file, though every
// one is a main() (witness: counted by function name, the two would be one row of 2).
TEST(Grader, ClassSummaryCountsEachPassApart) {
  fs::path dir = kit::test::temp_dir("grader-batch-passes");
  fs::path in = dir / "submissions", out = dir / "results";
  copy_lab("solutions", 5, in / "frank");
  edit(in / "frank" / "05-postprocess/bright.frag", "luminance > u_bloom_threshold ? c : vec3(0.0)", "c");
  copy_lab("solutions", 5, in / "grace");
  edit(in / "grace" / "05-postprocess/blur.frag", "(u_horizontal ? vec2(1.0, 0.0) : vec2(0.0, 1.0))", "vec2(1.0, 0.0)");
  std::string output;
  ASSERT_EQ(kit::test::run(kit::test::tool("kit-grade") + " --batch " + quoted(in) + " --out " + quoted(out) + " --labs 5",
                           &output), 0) << output;
  const std::string summary = read_file(out / "class-summary.csv");
  EXPECT_NE(summary.find("5,function,bright.frag,bright.frag,1,2\n"), std::string::npos) << summary;
  EXPECT_NE(summary.find("5,function,blur.frag,blur.frag,1,2\n"), std::string::npos) << summary;
  EXPECT_EQ(summary.find("5,function,main,"), std::string::npos) << summary;
  EXPECT_NE(read_file(out / "class-summary.html").find("<tr><td>main() (the whole pass)</td><td>blur.frag</td>"),
            std::string::npos);
}

// A batch: one result folder per submission, a gradebook, the class summary, and a second
// run that skips what is already graded.
TEST(Grader, BatchWritesAGradebookAndResumes) {
  fs::path dir = kit::test::temp_dir("grader-batch");
  fs::path in = dir / "submissions", out = dir / "results";
  copy_lab("solutions", 2, in / "alice");
  copy_lab("labs", 2, in / "bob");
  fs::create_directories(in / "carol");
  // dave and erin make the catalogue's lighting-f0-not-metallic (f0 0.04 for metals too).
  for (const char* name : {"dave", "erin"}) {
    copy_lab("solutions", 2, in / name);
    edit(in / name / "02-lighting/brdf.glsl", "vec3 f0 = mix(vec3(0.04), albedo, metallic);", "vec3 f0 = vec3(0.04);");
  }
  std::string output;
  std::string command = kit::test::tool("kit-grade") + " --batch " + quoted(in) + " --out " + quoted(out) + " --labs 2 --jobs 2";
  ASSERT_EQ(kit::test::run(command, &output), 0) << output;
  for (const char* name : {"alice", "bob", "carol", "dave", "erin"}) {
    expect_gradescope_schema(read_json(out / name / "results.json"));
    EXPECT_NE(output.find(std::string("] ") + name + ": "), std::string::npos) << output;
  }
  // The class: per lab the distribution, each check's passes, each mistake named first.
  const std::string summary = read_file(out / "class-summary.csv");
  EXPECT_NE(summary.find("lab,what,key,title,count,submissions\n"), std::string::npos) << summary;
  EXPECT_NE(summary.find("2,score,10,,1,5\n"), std::string::npos) << summary;   // alice alone has full marks
  EXPECT_NE(summary.find("2,score,0-1,,2,5\n"), std::string::npos) << summary;  // bob, carol
  EXPECT_NE(summary.find("2,check,default-final,\"default scene, final image\",1,5\n"), std::string::npos) << summary;
  EXPECT_NE(summary.find("2,mistake,lighting-f0-not-metallic,"), std::string::npos) << summary;
  EXPECT_NE(summary.find(",2,5\n", summary.find("2,mistake,lighting-f0-not-metallic,")), std::string::npos) << summary;
  EXPECT_NE(summary.find("2,mistake,starter-lab2,"), std::string::npos) << summary;
  // The functions that differ (function_probes.h): cook_torrance for dave, erin and bob's
  // starter, GGX for the starter alone; and dave's results name the function with inputs.
  EXPECT_NE(summary.find("2,function,cook_torrance,brdf.glsl,3,5\n"), std::string::npos) << summary;
  EXPECT_NE(summary.find("2,function,distribution_ggx,brdf.glsl,1,5\n"), std::string::npos) << summary;
  const json functions = read_json(out / "dave" / "summary.json")["labs"]["2"]["functions_text"];
  // Then its term probe (term_probes.h): F, D and G agree, so the term that differs is named.
  ASSERT_EQ(functions.size(), 2u) << functions;
  EXPECT_EQ(functions[0].get<std::string>().rfind("Your function cook_torrance(n = (0, 0, 1)", 0), 0u) << functions;
  EXPECT_EQ(functions[1].get<std::string>().rfind("Your function cook_torrance, term by term: a metal's F0 is not its albedo", 0),
            0u) << functions;
  EXPECT_NE(read_file(out / "dave" / "results.json").find("Your function cook"), std::string::npos);
  // A failed check names its worst pixel, with the G-buffer's inputs there where the scene's
  // references hold them (the default scene's); a passed one names none.
  const json dave = read_json(out / "dave" / "summary.json")["labs"]["2"]["checks"];
  const std::string worst = dave["default-hdr"].value("worst_pixel", std::string());
  EXPECT_FALSE(dave["default-hdr"].value("passed", true));
  EXPECT_NE(worst.find("the worst pixel, ("), std::string::npos) << worst;
  EXPECT_NE(worst.find("there the G-buffer holds position"), std::string::npos) << worst;
  EXPECT_NE(worst.find("metallic 1"), std::string::npos) << worst;  // the mistake shows on metals
  EXPECT_FALSE(read_json(out / "alice" / "summary.json")["labs"]["2"]["checks"]["default-hdr"].contains("worst_pixel"));
  // The report rings it on the difference image, at the pixel the text names.
  const std::string report = read_file(out / "dave" / "report.html");
  const size_t at = worst.find("the worst pixel, (");
  ASSERT_NE(at, std::string::npos);
  const std::string where = worst.substr(at, worst.find(')', at) + 1 - at);
  EXPECT_NE(report.find("class=\"worst\""), std::string::npos);
  EXPECT_NE(report.find("title=\"" + where + "\""), std::string::npos) << where;
  EXPECT_EQ(read_file(out / "alice" / "report.html").find("class=\"worst\""), std::string::npos);
  const std::string page = read_file(out / "class-summary.html");
  EXPECT_NE(page.find("<svg role=\"img\""), std::string::npos);
  EXPECT_EQ(page.find("http"), std::string::npos) << "the page loads nothing from elsewhere";
  std::string csv = read_file(out / "gradebook.csv");
  EXPECT_NE(csv.find("submission,lab2,total,max_total,problems\n"), std::string::npos) << csv;
  EXPECT_NE(csv.find("alice,10,10,10,\n"), std::string::npos) << csv;
  EXPECT_NE(csv.find("bob,0,0,10,\n"), std::string::npos) << csv;
  EXPECT_NE(csv.find("carol,0,0,10,lab2:missing_files\n"), std::string::npos) << csv;
  auto stamp = fs::last_write_time(out / "alice" / "results.json");
  ASSERT_EQ(kit::test::run(command, &output), 0) << output;
  EXPECT_NE(output.find("0 to grade, 5 already graded"), std::string::npos) << output;
  EXPECT_EQ(fs::last_write_time(out / "alice" / "results.json"), stamp);
  ASSERT_EQ(kit::test::run(command + " --force", &output), 0) << output;
  EXPECT_NE(output.find("5 to grade"), std::string::npos) << output;
}

TEST(Grader, BadArgumentsFailWithAMessage) {
  std::string output;
  EXPECT_EQ(kit::test::run(kit::test::tool("kit-grade") + " --labs 9 x", &output), 2);
  EXPECT_NE(output.find("unknown stage '9'"), std::string::npos) << output;
  EXPECT_EQ(kit::test::run(kit::test::tool("kit-grade") + " --batch /nonexistent-folder --out /tmp", &output), 2);
  EXPECT_EQ(kit::test::run(kit::test::tool("kit-grade") + " " + quoted(kit::kit_root() / "solutions") +
                               " --out /proc/kit-grade-cannot-write",
                           &output),
            2);
  EXPECT_NE(output.find("cannot"), std::string::npos) << output;
}


// A render worker renders a submission's labs one after another in one process
// (render_worker.h). A lab that ends its worker abnormally after another lab is rendered
// again alone, since RLIMIT_AS and whatever state a crash follows from span the worker's
// life; as the first lab of a worker, or stopped by a limit that counts from its own
// start, its verdict stands.
TEST(Grader, OnlyAWorkersLaterCrashesAreRenderedAgainAlone) {
  using kit::grade::Outcome;
  auto ended = [](Outcome::Kind kind, int code) {
    Outcome o;
    o.kind = kind;
    o.code = code;
    return o;
  };
  for (const Outcome& o : {ended(Outcome::Kind::Signaled, SIGSEGV), ended(Outcome::Kind::OutOfMemory, 86),
                           ended(Outcome::Kind::Exited, 1)}) {
    EXPECT_TRUE(kit::grade::render_again_alone(o, 1)) << o.describe();
    EXPECT_TRUE(kit::grade::render_again_alone(o, 6)) << o.describe();
    EXPECT_FALSE(kit::grade::render_again_alone(o, 0)) << o.describe();
  }
  for (const Outcome& o : {ended(Outcome::Kind::TimedOut, 0), ended(Outcome::Kind::CpuLimit, SIGXCPU)})
    EXPECT_FALSE(kit::grade::render_again_alone(o, 3)) << o.describe();
}

// ---------------------------------------------------------------------------
// The grader's verdicts and scores, called directly (kit_grade_core): synthetic
// image pairs for the criteria, and every subset of failing checks for the sums.

namespace {

using kit::grade::Metric;
using kit::grade::Thousandths;

const kit::grade::Config& grading_config() {
  static const kit::grade::Config config = kit::grade::load_config(kit::grade::default_config_path());
  return config;
}

constexpr int kW = kit::grade::kGradeWidth, kH = kit::grade::kGradeHeight;
constexpr size_t kPixels = static_cast<size_t>(kW) * kH;

// A display image like the grader's: a background colour on the top third, a smooth
// gradient (the "scene") below it.
kit::Image synthetic_ldr() {
  kit::Image image(kW, kH, 4);
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      bool covered = y >= kH / 3;
      for (int c = 0; c < 3; ++c)
        image.at(x, y, c) = covered ? 0.2f + 0.5f * static_cast<float>(x) / kW + 0.1f * static_cast<float>(c) : 0.05f;
      image.at(x, y, 3) = 1.0f;
    }
  return image;
}

// `image` with `offset` added to the RGB of `count` covered pixels, spread evenly over them.
kit::Image with_offset(kit::Image image, float offset, size_t count) {
  const size_t covered = static_cast<size_t>(kW) * static_cast<size_t>(kH - kH / 3);
  const size_t stride = std::max<size_t>(1, covered / std::max<size_t>(1, count));
  size_t done = 0;
  for (size_t i = 0; i < covered && done < count; i += stride, ++done) {
    int x = static_cast<int>(i % kW), y = kH / 3 + static_cast<int>(i / kW);
    for (int c = 0; c < 3; ++c) image.at(x, y, c) += offset;
  }
  return image;
}

}  // namespace

// A fifth of the pixels off by 3/255 stays under the per-pixel threshold (0.02, about
// 5/255) everywhere, so the failing share and hard_fail pass it; the mean error over
// the covered pixels fails it. The same offset on a few pixels passes, and so does a
// larger one on fewer pixels than the failing share allows.
TEST(GraderVerdicts, WideFaintOffsetFailsTheMeanErrorAndAFewPixelsPass) {
  const kit::grade::Tolerance& tol = grading_config().tolerance(Metric::Ldr);
  ASSERT_GT(tol.max_mean_error, 0.0);
  const kit::Image reference = synthetic_ldr();
  const kit::Image wide = with_offset(reference, 3.0f / 255.0f, kPixels / 5);

  kit::grade::Comparison c = kit::grade::compare_images(Metric::Ldr, tol, wide, reference);
  EXPECT_FALSE(c.passed) << c.summary;
  EXPECT_EQ(c.failing_pixels, 0u) << "every pixel is under the per-pixel threshold";
  EXPECT_LE(c.max_error, tol.fail_threshold);
  EXPECT_GT(c.covered_mean_error, tol.max_mean_error);
  EXPECT_NE(c.summary.find("Over the limit: the mean error over the "), std::string::npos) << c.summary;
  EXPECT_NE(c.summary.find("a faint difference spread over many pixels"), std::string::npos) << c.summary;
  // Witness: the criteria kit-grade had before the mean error pass it.
  kit::grade::Tolerance old = tol;
  old.max_mean_error = 1e30;
  EXPECT_TRUE(kit::grade::compare_images(Metric::Ldr, old, wide, reference).passed);

  // The same offset on a few pixels: far under the mean error's limit.
  kit::grade::Comparison few = kit::grade::compare_images(Metric::Ldr, tol, with_offset(reference, 3.0f / 255.0f, 20), reference);
  EXPECT_TRUE(few.passed) << few.summary;
  EXPECT_LT(few.covered_mean_error, tol.max_mean_error / 10.0);
  // Over the per-pixel threshold on as many pixels as the failing share allows: passes
  // (each pixel counts at most fail_threshold towards the mean); one more fails.
  const size_t allowed = kit::grade::allowed_failing_pixels(tol, kPixels);
  EXPECT_EQ(allowed, 24u) << "0.05 % of 256 x 192, rounded down";
  kit::grade::Comparison at_allowance =
      kit::grade::compare_images(Metric::Ldr, tol, with_offset(reference, 0.2f, allowed), reference);
  EXPECT_TRUE(at_allowance.passed) << at_allowance.summary;
  EXPECT_EQ(at_allowance.failing_pixels, allowed);
  kit::grade::Comparison over =
      kit::grade::compare_images(Metric::Ldr, tol, with_offset(reference, 0.2f, allowed + 1), reference);
  EXPECT_FALSE(over.passed);
  EXPECT_LE(over.covered_mean_error, tol.max_mean_error) << "only the failing share fails it";

  // HDR: the same story after c / (1 + |c|).
  const kit::grade::Tolerance& hdr = grading_config().tolerance(Metric::Hdr);
  kit::Image hdr_reference = synthetic_ldr();
  for (float& v : hdr_reference.pixels) v *= 2.0f;
  kit::Image hdr_wide = hdr_reference;
  for (int y = kH / 3; y < kH; ++y)  // a fifth of the image: the covered rows' first 30 %
    for (int x = 0; x < kW * 3 / 10; ++x)
      for (int c = 0; c < 3; ++c) hdr_wide.at(x, y, c) *= 1.012f;
  kit::grade::Comparison h = kit::grade::compare_images(Metric::Hdr, hdr, hdr_wide, hdr_reference);
  EXPECT_EQ(h.failing_pixels, 0u) << h.summary;
  EXPECT_FALSE(h.passed) << h.summary;
}

// A run finds each reference's background once (reference_background) and passes it in:
// the same covered pixels and verdict as compare_images finding it itself. The background
// is the HDR reference's top third as compared (c / (1 + c) of 0.1); the witness, a wrong
// background, counts other pixels as covered.
// A scene with a vertical edge at column `edge`: a lit gradient on the left, background on
// the right, as a silhouette looks. RGBA, like the display images.
kit::Image edge_scene(int edge, float darken_inside = 0.0f) {
  kit::Image image(kW, kH, 4);
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      const bool inside = x < edge;
      for (int c = 0; c < 3; ++c)
        image.at(x, y, c) = inside ? 0.3f + 0.4f * static_cast<float>(y) / kH - (x < edge / 2 ? darken_inside : 0.0f)
                                   : 0.05f;
      image.at(x, y, 3) = 1.0f;
    }
  return image;
}

// Pixels with a channel more than `threshold` apart: the plain comparison, without the
// edge tolerance, as the grader counted them before.
size_t plainly_failing(const kit::Image& a, const kit::Image& b, double threshold) {
  size_t count = 0;
  for (int y = 0; y < a.height; ++y)
    for (int x = 0; x < a.width; ++x) {
      bool fails = false;
      for (int c = 0; c < a.channels; ++c) fails = fails || std::fabs(a.at(x, y, c) - b.at(x, y, c)) > threshold;
      count += fails;
    }
  return count;
}

// GL leaves a triangle edge's sub-pixel placement to the implementation: a silhouette
// drawn one pixel over is correct there. Witness: the plain comparison fails a whole
// column of 192 pixels (24 allowed). The kit's passes it, and still fails the edge moved
// three pixels, or the inside of the surface darkened.
TEST(GraderVerdicts, AnEdgeOnePixelOverPassesAndMovedOrInteriorChangesFail) {
  const kit::grade::Tolerance& tol = grading_config().tolerance(Metric::Ldr);
  const kit::Image reference = edge_scene(100);
  const kit::Image one_over = edge_scene(101);
  EXPECT_EQ(plainly_failing(one_over, reference, tol.fail_threshold), static_cast<size_t>(kH));
  EXPECT_GT(plainly_failing(one_over, reference, tol.fail_threshold), kit::grade::allowed_failing_pixels(tol, kPixels));

  kit::grade::Comparison shifted = kit::grade::compare_images(Metric::Ldr, tol, one_over, reference);
  EXPECT_TRUE(shifted.passed) << shifted.summary;
  EXPECT_EQ(shifted.failing_pixels, 0u);
  EXPECT_EQ(shifted.edge_pixels, static_cast<size_t>(kH)) << "the column the edge moved into";
  EXPECT_NE(shifted.summary.find("192 pixels at edges of the reference are within its values one pixel over"),
            std::string::npos) << shifted.summary;

  kit::grade::Comparison moved = kit::grade::compare_images(Metric::Ldr, tol, edge_scene(103), reference);
  EXPECT_FALSE(moved.passed) << moved.summary;
  EXPECT_EQ(moved.failing_pixels, 2u * kH) << "the two columns beyond the neighbourhood";

  kit::grade::Comparison darker = kit::grade::compare_images(Metric::Ldr, tol, edge_scene(100, 0.03f), reference);
  EXPECT_FALSE(darker.passed) << darker.summary;
  EXPECT_EQ(darker.failing_pixels, 50u * kH) << "the darkened half of the inside, none of it at an edge";

  // The same for normals: a silhouette of the +Z facing surface one pixel over passes.
  const kit::grade::Tolerance& normal_tol = grading_config().tolerance(Metric::Normal);
  auto normals = [](int edge) {
    kit::Image image(kW, kH, 4);
    for (int y = 0; y < kH; ++y)
      for (int x = 0; x < edge; ++x) image.at(x, y, 2) = 1.0f;
    return image;
  };
  kit::grade::Comparison normal_shift = kit::grade::compare_images(Metric::Normal, normal_tol, normals(101), normals(100));
  EXPECT_TRUE(normal_shift.passed) << normal_shift.summary;
  EXPECT_EQ(normal_shift.edge_pixels, static_cast<size_t>(kH));
  EXPECT_FALSE(kit::grade::compare_images(Metric::Normal, normal_tol, normals(103), normals(100)).passed);
}

// A reference's filter allowance (references.h): where the solutions' own render moves
// under GPU-like filtering, a submission's difference counts that much less. A render
// that moves as the solutions' does passes; the same difference beyond the allowance, or
// where the allowance is 0, fails. pixel_differences is what the allowance is made of.
TEST(GraderVerdicts, FilterAllowanceForgivesOnlyTheReferencesOwnSpread) {
  const kit::grade::Tolerance& tol = grading_config().tolerance(Metric::Ldr);
  const kit::Image reference = synthetic_ldr();
  const kit::Image filtered = with_offset(reference, 0.1f, 500);  // texel pixels another filter moves
  kit::grade::Comparison plain = kit::grade::compare_images(Metric::Ldr, tol, filtered, reference);
  EXPECT_FALSE(plain.passed) << "witness: 500 pixels 0.1 off fail without an allowance";
  const kit::Image allowance = kit::grade::pixel_differences(Metric::Ldr, filtered, reference);
  ASSERT_EQ(allowance.channels, 1);
  size_t moved = 0;
  for (float v : allowance.pixels) moved += v > 0.0f;
  EXPECT_EQ(moved, 500u);
  kit::grade::Comparison allowed = kit::grade::compare_images(Metric::Ldr, tol, filtered, reference, nullptr, &allowance);
  EXPECT_TRUE(allowed.passed) << allowed.summary;
  EXPECT_EQ(allowed.filter_pixels, 500u);
  EXPECT_NE(allowed.summary.find("500 pixels are within the reference's own spread"), std::string::npos) << allowed.summary;
  // Twice as far off at the same pixels: 0.1 over the allowance, over the threshold.
  EXPECT_FALSE(kit::grade::compare_images(Metric::Ldr, tol, with_offset(reference, 0.2f, 500), reference, nullptr,
                                          &allowance).passed);
  // A faint offset everywhere else still fails the mean error: the allowance is per pixel.
  kit::Image wide = with_offset(reference, 3.0f / 255.0f, kPixels / 5);
  EXPECT_FALSE(kit::grade::compare_images(Metric::Ldr, tol, wide, reference, nullptr, &allowance).passed);

  // Normals: 2.7 degrees off on a band where the allowance is 2.5 passes; 6 fails.
  const kit::grade::Tolerance& normal_tol = grading_config().tolerance(Metric::Normal);
  auto tilted = [](double degrees) {
    kit::Image image(kW, kH, 4);
    for (int y = 0; y < kH; ++y)
      for (int x = 0; x < kW; ++x) {
        const double a = x < 40 ? degrees * 3.14159265358979 / 180.0 : 0.0;
        image.at(x, y, 0) = static_cast<float>(std::sin(a));
        image.at(x, y, 2) = static_cast<float>(std::cos(a));
      }
    return image;
  };
  const kit::Image flat = tilted(0.0);
  const kit::Image normal_allowance = kit::grade::pixel_differences(Metric::Normal, tilted(2.5), flat);
  EXPECT_NEAR(normal_allowance.at(0, 0, 0), 2.5f, 1e-3f);
  EXPECT_FALSE(kit::grade::compare_images(Metric::Normal, normal_tol, tilted(2.7), flat).passed) << "witness";
  const kit::grade::Comparison within = kit::grade::compare_images(Metric::Normal, normal_tol, tilted(2.7), flat, nullptr, &normal_allowance);
  EXPECT_TRUE(within.passed) << within.summary;
  EXPECT_FALSE(kit::grade::compare_images(Metric::Normal, normal_tol, tilted(6.0), flat, nullptr, &normal_allowance).passed);
}

// The similarity of two mistakes' signatures, against numbers worked by hand: the cosine
// of the concatenated checks, a check one side lacks counted as zeros.
TEST(GraderVerdicts, SignatureSimilarityAndNaming) {
  using Signatures = std::map<std::string, std::vector<float>>;
  const Signatures a = {{"x", {1.0f, 0.0f}}}, b = {{"x", {0.0f, 1.0f}}}, c = {{"x", {1.0f, 1.0f}}};
  EXPECT_DOUBLE_EQ(kit::grade::signature_similarity(a, a), 1.0);
  EXPECT_DOUBLE_EQ(kit::grade::signature_similarity(a, b), 0.0);
  EXPECT_NEAR(kit::grade::signature_similarity(a, c), 0.70710678, 1e-7);  // 1 / sqrt(2)
  EXPECT_NEAR(kit::grade::signature_similarity({{"x", {1.0f}}, {"y", {1.0f}}}, {{"x", {1.0f}}}), 0.70710678, 1e-7);
  EXPECT_DOUBLE_EQ(kit::grade::signature_similarity(a, {{"x", {0.0f, 0.0f}}}), 0.0) << "no error: nothing alike";
  // Longer on one side (lab 7's volume evidence, which a browser cannot count): the signature
  // both have and the failed flags (last). Tile 1, evidence 5 and flag 0.5 against tile 1 and
  // flag 0.5: the evidence left out, (1 + 0.25) / (1.25) = 1; counted as zeros it would be
  // 1.25 / sqrt(26.25 x 1.25) = 0.218. Witness: the same lengths keep every value.
  EXPECT_DOUBLE_EQ(kit::grade::signature_similarity({{"x", {1.0f, 5.0f, 0.5f}}}, {{"x", {1.0f, 0.5f}}}), 1.0);
  EXPECT_DOUBLE_EQ(kit::grade::signature_similarity({{"x", {1.0f, 0.5f}}}, {{"x", {1.0f, 5.0f, 0.5f}}}), 1.0);
  EXPECT_NEAR(kit::grade::signature_similarity({{"x", {1.0f, 5.0f, 0.5f}}}, {{"x", {1.0f, 0.0f, 0.5f}}}),
              1.25 / std::sqrt(26.25 * 1.25), 1e-7);
  // Features (kit::grade::check_features): sqrt(tile / cap) per tile, then the failed flag.
  const std::vector<float> f = kit::grade::check_features({0.0f, kit::grade::kSignatureCap / 4.0f, 9.0f}, true);
  ASSERT_EQ(f.size(), 4u);
  EXPECT_FLOAT_EQ(f[0], 0.0f);
  EXPECT_FLOAT_EQ(f[1], 0.5f) << "a quarter of the cap: its square root";
  EXPECT_FLOAT_EQ(f[2], 1.0f) << "capped";
  EXPECT_FLOAT_EQ(f[3], kit::grade::kFailedWeight);
  EXPECT_FLOAT_EQ(kit::grade::check_features({}, false).at(0), 0.0f) << "a check with no image: its flag only";
  // Naming: the closest, then the closest of each other family above the floor.
  const Signatures d = {{"x", {1.0f, 0.1f}}}, e = {{"x", {0.8f, 0.6f}}};  // 0.995 and 0.8 like a
  kit::grade::MistakeSignatures catalogue;
  catalogue.labs[2] = {{"far", "far off", "2.f", b, false, {}},     {"close", "close", "2.c", c, false, {}},
                       {"same", "the same", "2.s", a, false, {}},    {"next", "next to it", "2.s", d, false, {}},
                       {"other", "another term", "2.o", e, false, {}}};
  const auto named = kit::grade::likely_mistakes(catalogue, 2, a);
  ASSERT_EQ(named.size(), 3u);
  EXPECT_EQ(named[0].id, "same");
  EXPECT_EQ(named[1].id, "other") << "'next' (0.995) is of the family already named";
  EXPECT_EQ(named[2].id, "close");
  EXPECT_TRUE(kit::grade::likely_mistakes(catalogue, 2, {{"x", {-1.0f, -1.0f}}}).empty()) << "below the floor";
  EXPECT_TRUE(kit::grade::likely_mistakes(catalogue, 3, a).empty()) << "no signatures for that lab";
  // The function probes (function_probes.h) tell apart two mistakes with the same images: the
  // one whose differing function is the submission's goes first, and without probes the order
  // stays the file's.
  kit::grade::MistakeSignatures twins;
  twins.labs[2] = {{"no-4", "the specular term without its 4", "2.d", a, true, {"cook_torrance"}},
                   {"ggx-no-pi", "GGX without its pi", "2.g", a, true, {"cook_torrance", "distribution_ggx"}}};
  const std::set<std::string> ggx = {"cook_torrance", "distribution_ggx"};
  EXPECT_EQ(kit::grade::likely_mistakes(twins, 2, a, &ggx).at(0).id, "ggx-no-pi");
  EXPECT_EQ(kit::grade::likely_mistakes(twins, 2, a).at(0).id, "no-4");
  EXPECT_DOUBLE_EQ(kit::grade::likely_mistakes(twins, 2, a, &ggx).at(0).similarity, 1.0) << "the images' similarity, as shown";
}

// Metric::Same compares two renders of one submission, made on one machine: exact, with
// no edge tolerance. One pixel one 8-bit step off fails it.
TEST(GraderVerdicts, SameIsExactAndIgnoresEdges) {
  const kit::grade::Tolerance& tol = grading_config().tolerance(Metric::Same);
  const kit::Image image = edge_scene(100);
  EXPECT_TRUE(kit::grade::compare_images(Metric::Same, tol, image, image).passed);
  kit::Image step = image;
  step.at(10, 10, 0) += 1.0f / 255.0f;
  EXPECT_FALSE(kit::grade::compare_images(Metric::Same, tol, step, image).passed);
  kit::grade::Comparison shifted = kit::grade::compare_images(Metric::Same, tol, edge_scene(101), image);
  EXPECT_FALSE(shifted.passed) << "a ripple that moves the image by a pixel is not the image";
  EXPECT_EQ(shifted.edge_pixels, 0u);
}

// grading.json names the implementations its tolerances were measured on, and a check may
// carry its own tolerance (the fields given replace its metric's).
TEST(GraderVerdicts, MeasuredImplementationsAndCheckTolerancesComeFromGradingJson) {
  const kit::grade::Config& config = grading_config();
  EXPECT_TRUE(config.measured_on_renderer("osmesa: llvmpipe (LLVM 15.0.6, 256 bits) / 4.5 (Core Profile) Mesa 22.3.6"));
  EXPECT_TRUE(config.measured_on_renderer(
      "egl: llvmpipe (LLVM 19.1.7, 256 bits) / 4.5 (Core Profile) Mesa 25.0.7-2+deb13u1"));
  EXPECT_TRUE(config.measured_on_renderer("osmesa: softpipe / 3.3 (Core Profile) Mesa 22.3.6"));
  EXPECT_TRUE(config.measured_on_renderer("egl: zink (llvmpipe (LLVM 15.0.6, 256 bits)) / 4.6 (Core Profile) Mesa 22.3.6"));
  EXPECT_FALSE(config.measured_on_renderer("egl: llvmpipe (LLVM 17.0.6, 256 bits) / 4.5 (Core Profile) Mesa 24.2.8"));
  EXPECT_FALSE(config.measured_on_renderer("egl: NVIDIA H100 80GB HBM3/PCIe/SSE2 / 4.6.0 NVIDIA 580.65.06"));
  EXPECT_FALSE(config.measured_on_renderer(""));
  EXPECT_NE(config.measured_on_text().find("softpipe, Mesa 22.3"), std::string::npos);

  const kit::grade::Check* highlight = nullptr;
  const kit::grade::Check* studio = nullptr;
  for (const kit::grade::Check* c : kit::grade::lab_checks(6)) {
    if (c->key == "highlight-sun-hdr") highlight = c;
    if (c->key == "default-studio-hdr") studio = c;
  }
  ASSERT_TRUE(highlight && studio);
  const kit::grade::Tolerance& hdr = config.tolerance(Metric::Hdr);
  EXPECT_GT(config.tolerance(*highlight).fail_percent, hdr.fail_percent);
  EXPECT_EQ(config.tolerance(*highlight).fail_threshold, hdr.fail_threshold) << "a field not given is the metric's";
  EXPECT_EQ(&config.tolerance(*studio), &hdr) << "a check without its own tolerance has its metric's";
}

TEST(GraderVerdicts, ReferenceBackgroundFoundOnceIsTheOneCompareFinds) {
  const kit::grade::Tolerance& tol = grading_config().tolerance(Metric::Hdr);
  kit::Image reference = synthetic_ldr();
  for (float& v : reference.pixels) v *= 2.0f;
  const kit::Image image = with_offset(reference, 0.01f, kPixels / 5);
  const kit::grade::Background background = kit::grade::reference_background(Metric::Hdr, reference);
  EXPECT_FLOAT_EQ(background[0], 0.1f / 1.1f);
  EXPECT_FLOAT_EQ(background[3], 2.0f) << "alpha as it is";
  const kit::grade::Comparison found = kit::grade::compare_images(Metric::Hdr, tol, image, reference);
  const kit::grade::Comparison given = kit::grade::compare_images(Metric::Hdr, tol, image, reference, &background);
  EXPECT_EQ(given.covered_pixels, found.covered_pixels);
  EXPECT_EQ(given.covered_mean_error, found.covered_mean_error);
  EXPECT_EQ(given.passed, found.passed);
  EXPECT_EQ(found.covered_pixels, static_cast<size_t>(kW) * static_cast<size_t>(kH - kH / 3));
  const kit::grade::Background wrong{0.0f, 0.0f, 0.0f, 0.0f};
  EXPECT_EQ(kit::grade::compare_images(Metric::Hdr, tol, image, reference, &wrong).covered_pixels, kPixels);
}

// The background is the most common pixel, whichever way it is found: the one-pass
// majority of the top-left pixel's value, or the sort when that value is not over half.
TEST(GraderVerdicts, ReferenceBackgroundIsTheMostCommonPixelWhereverTheCornerIs) {
  auto image_of = [](const std::vector<float>& values) {  // one grey pixel per value, in a row
    kit::Image image(static_cast<int>(values.size()), 1, 4);
    for (size_t x = 0; x < values.size(); ++x)
      for (int c = 0; c < 4; ++c) image.at(static_cast<int>(x), 0, c) = values[x];
    return image;
  };
  auto grey = [](const kit::grade::Background& b) { return b[0]; };
  // The corner's value over half: it.
  EXPECT_EQ(grey(kit::grade::reference_background(Metric::Ldr, image_of({0.5f, 0.5f, 0.5f, 0.2f, 0.2f}))), 0.5f);
  // The corner's value the most common but not over half: the sort finds it all the same.
  EXPECT_EQ(grey(kit::grade::reference_background(Metric::Ldr, image_of({0.5f, 0.5f, 0.2f, 0.3f, 0.4f}))), 0.5f);
  // Another value the most common: not the corner's.
  EXPECT_EQ(grey(kit::grade::reference_background(Metric::Ldr, image_of({0.5f, 0.2f, 0.2f, 0.2f, 0.5f, 0.1f}))), 0.2f);
  // Exactly half each: a tie, so the smaller, whichever is in the corner.
  EXPECT_EQ(grey(kit::grade::reference_background(Metric::Ldr, image_of({0.5f, 0.5f, 0.2f, 0.2f}))), 0.2f);
  EXPECT_EQ(grey(kit::grade::reference_background(Metric::Ldr, image_of({0.2f, 0.2f, 0.5f, 0.5f}))), 0.2f);
  // The count table is kept between calls: a grading-size image of distinct values but
  // one (0.75, four times), then the small ones again, each counted afresh.
  std::vector<float> many(256 * 192);
  for (size_t i = 0; i < many.size(); ++i) many[i] = static_cast<float>(i) / static_cast<float>(many.size());
  many[10] = many[500] = many[9000] = 0.75f;
  EXPECT_EQ(grey(kit::grade::reference_background(Metric::Ldr, image_of(many))), 0.75f);
  EXPECT_EQ(grey(kit::grade::reference_background(Metric::Ldr, image_of({0.5f, 0.5f, 0.2f, 0.3f, 0.4f}))), 0.5f);
  EXPECT_EQ(grey(kit::grade::reference_background(Metric::Ldr, image_of({0.5f, 0.2f, 0.2f, 0.2f, 0.5f, 0.1f}))), 0.2f);
}

// The report's PNGs are written fast (zlib level 1, every row Sub-filtered) and still
// hold exactly the 8-bit values the other effort writes: round to nearest, clamped.
// compare_images computes idiff's statistics itself and maps the diff through a table of
// OpenImageIO's inferno map: both checked against OpenImageIO's own ImageBufAlgo::compare
// and color_map on an image pair with scattered errors, some over the threshold, and two
// pixels tied for the largest (the first in rows is the one named).
TEST(GraderVerdicts, StatisticsAndDiffColoursAreOpenImageIOs) {
  const kit::grade::Tolerance& tol = grading_config().tolerance(Metric::Ldr);
  // A reference with no edge (every row covered, a gentle gradient): the counted error is
  // then the plain difference everywhere, as OpenImageIO's compare measures it.
  kit::Image reference = synthetic_ldr();
  for (int y = 0; y < kH / 3; ++y)
    for (int x = 0; x < kW; ++x)
      for (int c = 0; c < 4; ++c) reference.at(x, y, c) = reference.at(x, kH / 3, c);
  kit::Image image = reference;
  for (size_t i = 0; i < image.pixels.size(); i += 7) image.pixels[i] += static_cast<float>((i * 7919) % 101) / 2000.0f;
  image.at(200, 150, 1) = reference.at(200, 150, 1) + 0.75f;
  image.at(10, 100, 2) = reference.at(10, 100, 2) - 0.75f;  // the same difference, earlier in rows
  auto wrap = [](const kit::Image& i) {
    return OIIO::ImageBuf(OIIO::ImageSpec(i.width, i.height, i.channels, OIIO::TypeDesc::FLOAT),
                          const_cast<float*>(i.pixels.data()));
  };
  const float threshold = static_cast<float>(tol.fail_threshold);
  const OIIO::ImageBufAlgo::CompareResults oiio =
      OIIO::ImageBufAlgo::compare(wrap(image), wrap(reference), threshold, threshold);
  const kit::grade::Comparison r = kit::grade::compare_images(Metric::Ldr, tol, image, reference);
  ASSERT_GT(oiio.nfail, 0u);
  EXPECT_EQ(r.failing_pixels, oiio.nfail);
  EXPECT_EQ(r.max_error, oiio.maxerror);
  EXPECT_EQ(r.max_x, oiio.maxx);
  EXPECT_EQ(r.max_y, oiio.maxy);
  EXPECT_EQ(r.max_x, 10);
  EXPECT_EQ(r.mean_error, oiio.meanerror);
  EXPECT_EQ(r.psnr, oiio.PSNR);
  // Normals: the PSNR of their xyz values.
  const OIIO::ImageBufAlgo::CompareResults xyz =
      OIIO::ImageBufAlgo::compare(wrap(image), wrap(reference), 1.0f, 1.0f, OIIO::ROI(0, kW, 0, kH, 0, 1, 0, 3));
  EXPECT_EQ(kit::grade::compare_images(Metric::Normal, grading_config().tolerance(Metric::Normal), image, reference).psnr,
            xyz.PSNR);

  kit::Image scaled(kW, kH, 1);
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      float d = 0.0f;
      for (int c = 0; c < 4; ++c) d = std::max(d, std::fabs(image.at(x, y, c) - reference.at(x, y, c)));
      scaled.at(x, y, 0) = std::min(d * kit::grade::kDiffScale, 1.0f);
    }
  kit::Image colours(kW, kH, 3);
  OIIO::ImageBufAlgo::color_map(wrap(scaled), 0, "inferno")
      .get_pixels(OIIO::ROI(0, kW, 0, kH, 0, 1, 0, 3), OIIO::TypeDesc::FLOAT, colours.pixels.data());
  ASSERT_EQ(r.diff.pixels.size(), colours.pixels.size());
  float largest = 0.0f;
  for (size_t i = 0; i < colours.pixels.size(); ++i) largest = std::max(largest, std::fabs(r.diff.pixels[i] - colours.pixels[i]));
  EXPECT_LT(largest, 1e-6f);
}

// A run's references are decoded once and kept in the reference cache
// (load_lab_references). Witnesses that the cache is what is read, and that it is only a
// cache: a cached image that was altered comes back altered; a truncated one is decoded
// again and rewritten; a reference file that changes gets new cache files, and its old
// version's go. A background file of the wrong size is found again.
TEST(GraderVerdicts, CachedReferencesAreTheDecodedOnes) {
  const fs::path references = kit::test::temp_dir("grader-reference-cache-files");
  fs::copy(kit::kit_root() / "tools/grade/references", references, fs::copy_options::recursive);
  const fs::path cache = kit::test::temp_dir("grader-reference-cache");
  const std::string id = "lab2-default-final";
  auto load = [&] { return kit::grade::load_lab_references(references, 2, cache).at(id); };
  auto same_pixels = [](const kit::Image& a, const kit::Image& b) {
    return a.width == b.width && a.height == b.height && a.channels == b.channels &&
           std::memcmp(a.pixels.data(), b.pixels.data(), a.pixels.size() * sizeof(float)) == 0;
  };
  const kit::Image decoded = kit::read_image((references / (id + ".png")).string());
  const kit::grade::LoadedReference first = load();
  EXPECT_TRUE(same_pixels(first.image, decoded));
  fs::path raw = first.cache_stem;
  raw += ".raw";
  ASSERT_TRUE(fs::is_regular_file(raw));
  EXPECT_EQ(first.cache_stem.parent_path(), cache);
  const uintmax_t raw_size = fs::file_size(raw);

  kit::Image altered = decoded;
  altered.pixels[0] = 0.25f;
  kit::grade::write_raw_image(raw, altered);
  EXPECT_TRUE(same_pixels(load().image, altered)) << "the cache is read";
  fs::resize_file(raw, raw_size / 2);
  EXPECT_TRUE(same_pixels(load().image, decoded)) << "a damaged cache file is passed over";
  EXPECT_EQ(fs::file_size(raw), raw_size) << "and written again";

  const Metric metric = Metric::Ldr;
  const kit::grade::Background found = kit::grade::reference_background(metric, decoded);
  EXPECT_EQ(kit::grade::cached_background(first, metric), found);
  fs::path background = first.cache_stem;
  background += ".ldr.background";
  ASSERT_TRUE(fs::is_regular_file(background));
  write_file(background, "bad");
  EXPECT_EQ(kit::grade::cached_background(first, metric), found);
  EXPECT_EQ(fs::file_size(background), sizeof(kit::grade::Background));

  kit::write_image((references / (id + ".png")).string(), altered);
  const kit::grade::LoadedReference changed = load();
  EXPECT_NE(changed.cache_stem, first.cache_stem);
  EXPECT_TRUE(same_pixels(changed.image, kit::read_image((references / (id + ".png")).string())));
  EXPECT_FALSE(fs::exists(raw)) << "the old version's files are removed";
  EXPECT_FALSE(fs::exists(background));
  // An id that begins another's (lab2-default-final-x) is not taken for an old version of it.
  fs::path other_id = cache / ("lab2-default-final-x-" + std::string(40, 'a') + ".raw");
  write_file(other_id, "x");
  kit::write_image((references / (id + ".png")).string(), decoded);
  load();
  EXPECT_TRUE(fs::exists(other_id));
}

// --update-references writes a reference again only where its pixels changed: the
// references written again from their own pixels leave every file as it was, byte for
// byte, and one pixel changed rewrites that file alone. Witness: an EXR reference written
// again as it is does not keep its bytes, which is why the pixels decide.
TEST(GraderVerdicts, ReferencesWrittenAgainKeepTheFilesWhosePixelsDidNotChange) {
  const fs::path source = kit::kit_root() / "tools/grade/references";
  const fs::path references = kit::test::temp_dir("grader-references-written-again");
  fs::copy(source, references, fs::copy_options::recursive);
  std::map<std::string, kit::Image> renders, allowances;
  std::string exr_id;
  const std::string allowance_suffix = ".allowance.exr";  // the manifest's filter_allowance names them so
  for (const kit::grade::RenderSpec* spec : kit::grade::reference_renders()) {
    const std::string file = spec->id + "." + kit::grade::reference_extension(*spec);
    renders[spec->id] = kit::read_image((references / file).string());
    if (fs::exists(references / (spec->id + allowance_suffix)))
      allowances[spec->id] = kit::read_image((references / (spec->id + allowance_suffix)).string());
    if (exr_id.empty() && kit::grade::reference_extension(*spec) == "exr") exr_id = spec->id;
  }
  ASSERT_FALSE(exr_id.empty());
  ASSERT_FALSE(allowances.empty());
  auto bytes = [](const fs::path& path) { return read_file(path); };
  std::map<std::string, std::string> before;
  for (const auto& entry : fs::directory_iterator(references)) before[entry.path().filename().string()] = bytes(entry.path());

  const fs::path witness = kit::test::temp_dir("grader-references-exr-again") / "again.exr";
  kit::write_image(witness.string(), renders[exr_id]);
  EXPECT_NE(bytes(witness), before[exr_id + ".exr"]) << "witness: an EXR written again keeps its bytes, so this "
                                                          "test shows nothing";

  const std::string renderer = kit::grade::references_renderer(references);
  EXPECT_TRUE(kit::grade::write_references(references, renders, allowances, renderer).empty());
  for (const auto& entry : fs::directory_iterator(references))
    EXPECT_EQ(bytes(entry.path()), before[entry.path().filename().string()]) << entry.path();

  renders[exr_id].pixels[0] += 0.5f;
  const std::vector<std::string> changed = kit::grade::write_references(references, renders, allowances, renderer);
  EXPECT_EQ(changed, std::vector<std::string>{exr_id + ".exr"});
  EXPECT_NE(bytes(references / (exr_id + ".exr")), before[exr_id + ".exr"]);
  EXPECT_EQ(kit::read_image((references / (exr_id + ".exr")).string()).pixels[0], renders[exr_id].pixels[0]);
}

// The build prepares the references (kit-grade --prepare-references, tools/grade.cmake)
// as a run's cache would hold them, and a run reads them there without writing there.
// Witnesses: the prepared files are the cache's byte for byte; with them a run's cache
// gets no decoded reference; a reference file that changed since is decoded into the
// cache again (the prepared file's name holds the old version's digest).
TEST(GraderVerdicts, PreparedReferencesAreTheCachedOnes) {
  const fs::path references = kit::test::temp_dir("grader-prepared-files");
  fs::copy(kit::kit_root() / "tools/grade/references", references, fs::copy_options::recursive);
  const fs::path prepared = kit::test::temp_dir("grader-prepared");
  const fs::path cache = kit::test::temp_dir("grader-prepared-cache");
  const fs::path unprepared = kit::test::temp_dir("grader-unprepared-cache");
  kit::grade::Options options;
  options.references = references;
  options.labs = {2};
  EXPECT_EQ(kit::grade::prepare_references(options, prepared), 0);
  const auto read = kit::grade::load_lab_references(references, 2, cache, prepared);
  const auto decoded = kit::grade::load_lab_references(references, 2, unprepared);
  ASSERT_EQ(read.size(), decoded.size());
  for (const auto& [id, reference] : read) {
    const kit::grade::LoadedReference& other = decoded.at(id);
    EXPECT_TRUE(reference.prepared) << id;
    EXPECT_FALSE(other.prepared) << id;
    EXPECT_EQ(reference.cache_stem.parent_path(), prepared) << id;
    EXPECT_EQ(reference.cache_stem.filename(), other.cache_stem.filename()) << id;
    EXPECT_EQ(reference.image.pixels, other.image.pixels) << id;
    fs::path raw = reference.cache_stem, other_raw = other.cache_stem;
    raw += ".raw";
    other_raw += ".raw";
    EXPECT_EQ(read_file(raw), read_file(other_raw)) << id;
  }
  EXPECT_TRUE(fs::is_empty(cache)) << "nothing decoded into the run's cache";
  // Each check's background and report PNG were prepared: none is made at grading time.
  for (const kit::grade::Check* check : kit::grade::lab_checks(2)) {
    if (kit::grade::compares_own_renders(check->metric)) continue;
    fs::path stem = read.at(check->reference).cache_stem;
    for (const std::string what : {".background", ".png"}) {
      fs::path file = stem;
      file += std::string(".") + kit::grade::metric_name(check->metric) + what;
      EXPECT_TRUE(fs::is_regular_file(file)) << file;
    }
  }
  // A background the folder lacks is found, not written there.
  const std::string id = "lab2-default-final";
  fs::path background = read.at(id).cache_stem;
  background += ".ldr.background";
  fs::remove(background);
  EXPECT_EQ(kit::grade::cached_background(read.at(id), Metric::Ldr),
            kit::grade::reference_background(Metric::Ldr, decoded.at(id).image));
  EXPECT_FALSE(fs::exists(background));

  kit::Image changed = decoded.at(id).image;
  changed.pixels[0] = 0.25f;
  kit::write_image((references / (id + ".png")).string(), changed);
  const kit::grade::LoadedReference again = kit::grade::load_lab_references(references, 2, cache, prepared).at(id);
  EXPECT_FALSE(again.prepared);
  EXPECT_EQ(again.cache_stem.parent_path(), cache);
  EXPECT_EQ(again.image.pixels, kit::read_image((references / (id + ".png")).string()).pixels);
  EXPECT_NE(again.image.pixels, decoded.at(id).image.pixels);
  // Stale references (here one is missing) are not prepared, and the build goes on:
  // grading says why they are stale.
  fs::remove(references / (id + ".png"));
  const fs::path stale = kit::test::temp_dir("grader-prepared-stale");
  EXPECT_EQ(kit::grade::prepare_references(options, stale), 0);
  EXPECT_TRUE(fs::is_empty(stale));
}

// The longest children first (the last lab's), then the lab with the most checks (lab 1),
// so that its comparison is not left to run alone after every child has finished.
TEST(GraderVerdicts, LabsStartLongestFirstAndTheCostliestComparisonEarly) {
  using kit::grade::lab_start_order;
  EXPECT_EQ(lab_start_order({1, 2, 3, 4, 5, 6, 7}, 2), (std::vector<int>{7, 6, 1, 5, 4, 3, 2}));
  EXPECT_EQ(lab_start_order({1, 2, 3, 4, 5, 6, 7}, 1), (std::vector<int>{7, 1, 6, 5, 4, 3, 2}));
  EXPECT_EQ(lab_start_order({1, 2, 3}, 2), (std::vector<int>{3, 2, 1}));  // 1 starts as soon as it can anyway
  EXPECT_EQ(lab_start_order({2, 3, 4}, 2), (std::vector<int>{4, 3, 2}));  // lab 3 has the most: already early
  EXPECT_EQ(lab_start_order({5}, 2), (std::vector<int>{5}));
  EXPECT_TRUE(lab_start_order({}, 2).empty());
}

TEST(GraderVerdicts, FastestPngsHoldTheSameBytes) {
  kit::Image image(97, 31, 3);
  for (size_t i = 0; i < image.pixels.size(); ++i)
    image.pixels[i] = static_cast<float>((i * 7919) % 1021) / 1000.0f - 0.01f;  // a little under 0 and over 1
  const fs::path dir = kit::test::temp_dir("grader-fastest-png");
  kit::write_image((dir / "smallest.png").string(), image, kit::PngEffort::Smallest);
  kit::write_image((dir / "fastest.png").string(), image, kit::PngEffort::Fastest);
  const kit::Image smallest = kit::read_image((dir / "smallest.png").string());
  const kit::Image fastest = kit::read_image((dir / "fastest.png").string());
  ASSERT_EQ(fastest.pixels.size(), image.pixels.size());
  EXPECT_EQ(fastest.pixels, smallest.pixels);
  for (size_t i = 0; i < image.pixels.size(); ++i)
    ASSERT_EQ(std::lround(fastest.pixels[i] * 255.0f), std::lround(std::clamp(image.pixels[i], 0.0f, 1.0f) * 255.0f)) << i;
}

// to_unorm8 is std::lround of the clamped value times 255, without the library call:
// checked around every value k/255 and every half (k + 0.5)/255, where rounding decides,
// and over [0,1] at a stride (the whole range was checked once, in 5 s).
TEST(GraderVerdicts, Unorm8RoundsAsLroundDoes) {
  auto expected = [](float v) {
    v = std::isfinite(v) ? std::clamp(v, 0.0f, 1.0f) : 0.0f;
    return static_cast<unsigned char>(std::lround(v * 255.0f));
  };
  // Witness: floor(v * 255 + 0.5) rounds this one up (0.49999997 after scaling).
  const float witness = 0.0019607842f;
  ASSERT_NE(static_cast<int>(std::floor(witness * 255.0f + 0.5f)), expected(witness));
  EXPECT_EQ(kit::to_unorm8(witness), expected(witness));
  size_t checked = 0;
  for (int k = 0; k <= 510; ++k) {
    const float centre = static_cast<float>(k) / 510.0f;  // k/255 and (k + 0.5)/255
    float below = centre, above = centre;
    for (int step = 0; step < 256; ++step, below = std::nextafter(below, -1.0f), above = std::nextafter(above, 2.0f)) {
      for (float v : {below, above}) ASSERT_EQ(kit::to_unorm8(v), expected(v)) << v;
      checked += 2;
    }
  }
  for (uint32_t bits = 0; bits <= 0x3f800000u; bits += 997) {
    float v;
    std::memcpy(&v, &bits, sizeof v);
    ASSERT_EQ(kit::to_unorm8(v), expected(v)) << v;
  }
  for (float v : {-1.0f, 2.0f, std::nanf(""), INFINITY, -INFINITY}) EXPECT_EQ(kit::to_unorm8(v), expected(v)) << v;
  EXPECT_GT(checked, 200000u);
}

// The HDR hard_fail is not "off": compressed values lie in (-1, 1), so a pixel
// whose sign differs from the reference's can differ by more than 1. The message
// says which criterion failed, with pixel counts, never a passing share alone.
TEST(GraderVerdicts, MessagesNameTheCriterionThatFailed) {
  const kit::grade::Tolerance& tol = grading_config().tolerance(Metric::Hdr);
  ASSERT_LT(tol.hard_fail, kit::grade::largest_possible_difference(Metric::Hdr));
  // A 3x3 patch of radiance 3 with its sign flipped: its centre is not at an edge of the
  // reference (compare.cpp, is_edge), so it is measured in full; the eight around it are
  // measured from their neighbourhood and still fail the threshold.
  kit::Image reference = synthetic_ldr();
  kit::Image flipped = reference;
  for (int y = 99; y <= 101; ++y)
    for (int x = 9; x <= 11; ++x)
      for (int c = 0; c < 3; ++c) {
        reference.at(x, y, c) = 3.0f;
        flipped.at(x, y, c) = -3.0f;  // 0.75 vs -0.75 compressed
      }
  kit::grade::Comparison c = kit::grade::compare_images(Metric::Hdr, tol, flipped, reference);
  EXPECT_FALSE(c.passed);
  EXPECT_EQ(c.failing_pixels, 9u);
  EXPECT_NEAR(c.max_error, 1.5, 1e-6);
  EXPECT_LE(c.covered_mean_error, tol.max_mean_error);
  EXPECT_EQ(c.summary.rfind("Over the limit: the largest difference is 1.5 at (10, 100), over the limit of 1", 0), 0u)
      << c.summary;
  EXPECT_NE(c.summary.find("sign differs"), std::string::npos) << c.summary;
  EXPECT_EQ(c.summary.find("more than the 24"), std::string::npos) << "the share passed: " << c.summary;
  EXPECT_NE(c.summary.find("9 of 49152 pixels (0.018%) differ by more than 0.01 (at most 24 (0.05%) may)"),
            std::string::npos)
      << c.summary;

  // 25 failing pixels are 0.0509 %, which "%.2f" would print as the limit itself.
  kit::Image wrong = reference;
  for (int i = 0; i < 25; ++i)
    for (int ch = 0; ch < 3; ++ch) wrong.at(20 + i * 7, 120, ch) += 0.1f;
  kit::grade::Comparison share = kit::grade::compare_images(Metric::Hdr, tol, wrong, reference);
  EXPECT_FALSE(share.passed);
  EXPECT_NE(share.summary.find("Over the limit: 25 of 49152 pixels (0.051%) differ by more than 0.01, more than the "
                               "24 (0.05%) allowed"),
            std::string::npos)
      << share.summary;
  // A display image cannot differ by more than 1: there hard_fail 1.0 never fires,
  // and the message shows no limit for it.
  const kit::grade::Tolerance& ldr = grading_config().tolerance(Metric::Ldr);
  EXPECT_GE(ldr.hard_fail, kit::grade::largest_possible_difference(Metric::Ldr));
  kit::grade::Comparison l = kit::grade::compare_images(Metric::Ldr, ldr, synthetic_ldr(), synthetic_ldr());
  EXPECT_TRUE(l.passed);
  EXPECT_EQ(l.summary.find("Over the limit"), std::string::npos);
  EXPECT_NE(l.summary.find("the largest difference is 0 at (0, 0);"), std::string::npos) << l.summary;
}

// Lab 6's maps are compared at their own sizes (the irradiance map is 32x16, where
// the failing share allows no pixel at all); an image whose size differs from its
// reference's is not compared, and the note says so and what to run.
TEST(GraderVerdicts, MapsAreComparedAtTheirOwnSizeAndOtherSizesAreRefused) {
  const kit::grade::Tolerance& tol = grading_config().tolerance(Metric::Hdr);
  kit::Image map(32, 16, 4);
  for (size_t i = 0; i < map.pixels.size(); ++i) map.pixels[i] = 0.5f + static_cast<float>(i % 7);
  kit::grade::Comparison same = kit::grade::compare_images(Metric::Hdr, tol, map, map);
  EXPECT_TRUE(same.passed) << same.summary;
  EXPECT_EQ(same.allowed_failing_pixels, 0u);
  kit::Image one_off = map;
  one_off.at(3, 4, 0) += 1.0f;
  EXPECT_FALSE(kit::grade::compare_images(Metric::Hdr, tol, one_off, map).passed);

  kit::Image larger(64, 32, 4);
  kit::grade::Comparison c = kit::grade::compare_images(Metric::Hdr, tol, larger, map);
  EXPECT_FALSE(c.passed);
  EXPECT_EQ(c.note.rfind("the image is 64x32 with 4 channels, the reference 32x16 with 4 channels: nothing was compared", 0),
            0u)
      << c.note;
  EXPECT_NE(c.note.find("--update-references"), std::string::npos) << c.note;
  EXPECT_EQ(c.summary, c.note);
  // Its difference image is blank but writable: the report of every other check is still written.
  EXPECT_EQ(c.diff.width, 64);
  EXPECT_EQ(c.diff.height, 32);
  EXPECT_NO_THROW(kit::write_image((kit::test::temp_dir("grader-size-diff") / "diff.png").string(), c.diff,
                                   kit::PngEffort::Fastest));
}

// handouts/instructors.md's tolerance table says what grading.json holds, and calls
// a hard_fail "never fires" exactly when it is at or above the largest difference
// the metric can measure.
TEST(GraderVerdicts, InstructorsTableAgreesWithGradingJson) {
  const std::string doc = read_file(kit::kit_root() / "handouts" / "instructors.md");
  const std::map<std::string, Metric> metrics = {{"ldr", Metric::Ldr},           {"hdr", Metric::Hdr},
                                                 {"position", Metric::Position}, {"normal", Metric::Normal},
                                                 {"albedo", Metric::Albedo},     {"material", Metric::Material}};
  const size_t header = doc.find("| metric | fail_threshold | fail_percent | hard_fail | max_mean_error |");
  ASSERT_NE(header, std::string::npos) << "instructors.md has no tolerance table with these columns";
  auto first_number = [](const std::string& cell) {
    size_t at = cell.find_first_of("0123456789");
    return at == std::string::npos ? -1.0 : std::stod(cell.substr(at));
  };
  for (const auto& [name, metric] : metrics) {
    const size_t row = doc.find("\n| " + name + " |", header);
    ASSERT_NE(row, std::string::npos) << name;
    std::string line = doc.substr(row + 1, doc.find('\n', row + 1) - row - 1);
    std::vector<std::string> cells;
    for (size_t at = 1; at < line.size();) {
      size_t end = line.find('|', at);
      if (end == std::string::npos) break;
      cells.push_back(line.substr(at, end - at));
      at = end + 1;
    }
    ASSERT_GE(cells.size(), 5u) << line;
    const kit::grade::Tolerance& tol = grading_config().tolerance(metric);
    EXPECT_DOUBLE_EQ(first_number(cells[1]), tol.fail_threshold) << line;
    EXPECT_DOUBLE_EQ(first_number(cells[2]), tol.fail_percent) << line;
    EXPECT_DOUBLE_EQ(first_number(cells[3]), tol.hard_fail) << line;
    EXPECT_DOUBLE_EQ(first_number(cells[4]), tol.max_mean_error) << line;
    const bool never = tol.hard_fail >= kit::grade::largest_possible_difference(metric);
    EXPECT_EQ(cells[3].find("never fires") != std::string::npos, never) << line;
    EXPECT_EQ(cells[3].find("off"), std::string::npos) << "say when it fires: " << line;
  }
}

namespace {

// "6.667" -> 6667, exactly (no floating point).
Thousandths parse_points(const std::string& text) {
  size_t dot = text.find('.');
  Thousandths whole = std::stoll(text.substr(0, dot));
  if (dot == std::string::npos) return whole * 1000;
  std::string fraction = text.substr(dot + 1);
  fraction.resize(3, '0');
  return whole * 1000 + std::stoll(fraction);
}

// Every subset of failing checks for a lab of `points`: the lab's printed total is
// the exact sum of the checks' printed scores and one of the values the shares allow.
void expect_exact_scores(const std::vector<double>& points) {
  const size_t n = points.size();
  const std::vector<Thousandths> shares = kit::grade::apportion(10000, points);
  ASSERT_EQ(shares.size(), n);
  Thousandths sum = 0;
  for (Thousandths s : shares) sum += s;
  ASSERT_EQ(sum, 10000) << "the shares add up to the weight";
  std::vector<kit::grade::Check> checks;
  for (size_t i = 0; i < n; ++i)
    checks.push_back({3, "check-" + std::to_string(i), "check " + std::to_string(i), Metric::Ldr, "", ""});
  for (unsigned mask = 0; mask < (1u << n); ++mask) {
    kit::grade::SubmissionOutcome s;
    kit::grade::LabOutcome& lab = s.labs[3];
    lab.lab = 3;
    lab.status = kit::grade::kGraded;
    Thousandths expected = 0;
    for (size_t i = 0; i < n; ++i) {
      kit::grade::CheckOutcome c;
      c.check = &checks[i];
      c.compared = true;
      c.passed = (mask >> i) & 1u;
      c.max_score = shares[i];
      c.score = c.passed ? shares[i] : 0;
      expected += c.score;
      lab.checks.push_back(c);
    }
    ASSERT_EQ(lab.score(), expected);
    ASSERT_EQ(lab.max_score(), 10000);
    // The console line prints the total; results.json prints each check's score.
    const std::string line = kit::grade::lab_line(lab);
    const size_t colon = line.find(": "), slash = line.find('/');
    const Thousandths printed_total = parse_points(line.substr(colon + 2, slash - colon - 2));
    const json results = kit::grade::results_json(s);
    Thousandths printed_sum = 0;
    for (const json& t : results["tests"]) printed_sum += parse_points(t["score"].dump());
    EXPECT_EQ(printed_total, expected) << line;
    EXPECT_EQ(printed_sum, expected) << "mask " << mask;
    EXPECT_EQ(parse_points(results["score"].dump()), expected);
    EXPECT_EQ(parse_points(kit::grade::summary_json(s)["labs"]["3"]["score"].dump()), expected);
    EXPECT_EQ(line.substr(slash, 4), "/10 ") << line;
    // Equal points: k passing checks score k shares, each the exact share rounded down or up.
    if (std::all_of(points.begin(), points.end(), [&](double p) { return p == points[0]; })) {
      const Thousandths q = 10000 / static_cast<Thousandths>(n), r = 10000 % static_cast<Thousandths>(n);
      const Thousandths k = static_cast<Thousandths>(__builtin_popcount(mask));
      const Thousandths lo = k * q + std::max<Thousandths>(0, k - (static_cast<Thousandths>(n) - r));
      const Thousandths hi = k * q + std::min(k, r);
      EXPECT_GE(expected, lo);
      EXPECT_LE(expected, hi);
    }
  }
}

}  // namespace

// Scores are integer thousandths apportioned once per lab: whichever checks fail,
// the total printed is the exact sum of the scores printed, 3.333 + 3.333 is 6.666
// and never 6.666000000000001 or a console "6.67" beside a results.json 6.666.
TEST(GraderScores, TotalsAreExactForEverySubsetOfFailingChecks) {
  EXPECT_EQ(kit::grade::format_points(6667), "6.667");
  EXPECT_EQ(kit::grade::format_points(10000), "10");
  EXPECT_EQ(kit::grade::format_points(3500), "3.5");
  EXPECT_EQ(kit::grade::format_points(5), "0.005");
  EXPECT_EQ(kit::grade::format_points(0), "0");
  EXPECT_EQ(kit::grade::apportion(10000, {1, 1, 1}), (std::vector<Thousandths>{3334, 3333, 3333}));
  EXPECT_EQ(kit::grade::apportion(10000, {1, 1, 1, 1, 1, 1}),
            (std::vector<Thousandths>{1667, 1667, 1667, 1667, 1666, 1666}));
  EXPECT_EQ(kit::grade::apportion(10000, {2, 2, 2, 2, 2, 1, 1, 1}),
            (std::vector<Thousandths>{1539, 1539, 1539, 1538, 1538, 769, 769, 769}));
  expect_exact_scores({1, 1, 1});
  expect_exact_scores({1, 1, 1, 1, 1, 1});
  expect_exact_scores({1, 1, 1, 1, 1, 1, 1});
  // grading.json's own labs, as kit-grade apportions them.
  const kit::grade::Config& config = grading_config();
  for (const auto& [number, lab_points] : config.points) {
    std::vector<double> p;
    for (const auto& [key, value] : lab_points) p.push_back(value);
    expect_exact_scores(p);
    Thousandths sum = 0;
    for (const kit::grade::Check* c : kit::grade::lab_checks(number)) sum += config.max_score(*c);
    EXPECT_EQ(sum, static_cast<Thousandths>(std::llround(config.weight.at(number) * 1000))) << "lab " << number;
  }
}

// The G-buffers kept only to describe a worst pixel (checks.h, describes_pixels_only) hold
// what the scenes are built of (tools/scenes/scene_catalogue.cpp), not what a shader of the
// kit says: on the sphere scene every covered pixel lies on the unit sphere (within its 64 x
// 32 facets), its normal pointing away from the centre, terracotta (0.8, 0.3, 0.2), roughness
// 0.4, not metallic, not emissive; on the grazing scene on the plane y = 0, facing up, white,
// roughness 0.3. And every scene a lab 2-7 image renders has the five attachments.
TEST(GraderVerdicts, PixelDescribingReferencesHoldTheScenes) {
  for (const kit::grade::RenderSpec& spec : kit::grade::renders()) {
    if (spec.stage >= 2 && (spec.view == kit::View::Final || spec.view == kit::View::Hdr)) {
      EXPECT_EQ(kit::grade::gbuffer_reference_ids(spec).size(), 5u) << spec.id;
    }
  }
  const fs::path references = kit::kit_root() / "tools/grade/references";
  const auto read = [&](const std::string& id) { return kit::read_image((references / (id + ".exr")).string()); };
  struct Expected {
    std::string scene;
    std::function<std::string(const glm::dvec3& position, const glm::dvec3& normal)> geometry;
    glm::dvec3 albedo;
    double roughness;
  };
  const auto angle = [](const glm::dvec3& a, const glm::dvec3& b) {
    return glm::degrees(std::acos(std::clamp(glm::dot(glm::normalize(a), glm::normalize(b)), -1.0, 1.0)));
  };
  const std::vector<Expected> scenes = {
      {"sphere",
       [&](const glm::dvec3& p, const glm::dvec3& n) -> std::string {
         // A facet's middle lies at most 1 - cos(pi / 32) (0.5 %) inside the sphere.
         if (glm::length(p) < 0.994 || glm::length(p) > 1.0005) return "not on the unit sphere";
         return angle(n, p) > 3.0 ? "a normal not along the radius" : "";
       },
       {0.8, 0.3, 0.2}, 0.4},
      {"grazing",
       [&](const glm::dvec3& p, const glm::dvec3& n) -> std::string {
         if (std::abs(p.y) > 1e-4) return "not on the plane y = 0";
         return angle(n, {0, 1, 0}) > 0.1 ? "a normal not facing up" : "";
       },
       {1.0, 1.0, 1.0}, 0.3},
  };
  for (const Expected& e : scenes) {
    const kit::Image position = read("lab1-" + e.scene + "-position"), normal = read("lab1-" + e.scene + "-normal");
    const kit::Image albedo = read("lab1-" + e.scene + "-albedo"), material = read("lab1-" + e.scene + "-material");
    const kit::Image emission = read("lab1-" + e.scene + "-emission");
    int covered = 0, wrong = 0;
    std::string first;
    for (int y = 0; y < position.height; ++y)
      for (int x = 0; x < position.width; ++x) {
        if (material.at(x, y, 3) < 0.5f) continue;
        ++covered;
        const auto at = [&](const kit::Image& image) {
          return glm::dvec3(image.at(x, y, 0), image.at(x, y, 1), image.at(x, y, 2));
        };
        std::string why = e.geometry(at(position), at(normal));
        if (why.empty() && glm::length(at(albedo) - e.albedo) > 0.004) why = "another albedo";
        if (why.empty() && (std::abs(material.at(x, y, 0)) > 1e-6 || std::abs(material.at(x, y, 1) - e.roughness) > 1e-3))
          why = "another metallic or roughness";
        if (why.empty() && glm::length(at(emission)) > 1e-6) why = "emission";
        if (!why.empty() && wrong++ == 0) first = why + " at (" + std::to_string(x) + ", " + std::to_string(y) + ")";
      }
    EXPECT_GT(covered, 1000) << e.scene;
    EXPECT_EQ(wrong, 0) << e.scene << ": " << first;
  }
}

// --check-references compares the references no check compares too: one of them swapped for
// another scene's (the grazing plane's positions for the sphere's) is named stale. The
// unchanged references pass (the ctest grade_references_reproduce).
TEST(Grader, CheckReferencesComparesThoseThatDescribeAPixel) {
  const fs::path references = kit::test::temp_dir("grader-describing-stale");
  fs::copy(kit::kit_root() / "tools/grade/references", references, fs::copy_options::recursive);
  fs::copy_file(references / "lab1-grazing-position.exr", references / "lab1-sphere-position.exr",
                fs::copy_options::overwrite_existing);
  std::string output;
  EXPECT_EQ(kit::test::run(kit::test::tool("kit-grade") + " --check-references --references " + quoted(references), &output), 1)
      << output;
  EXPECT_NE(output.find("lab1-sphere-position (kept to describe a worst pixel): Over the limit"), std::string::npos) << output;
  EXPECT_EQ(output.find("lab1-grazing-position"), std::string::npos) << output;
}

// Where a scene has more lights than a worst pixel's description lists (lab 7's 128), it
// names the nearest, numbered as the scene lists them; a directional light comes first.
TEST(GraderVerdicts, PixelDescriptionNamesTheNearestLights) {
  kit::Scene scene;
  for (float x : {9.0f, 1.0f, 7.0f, 2.0f, 8.0f, 3.0f}) {
    kit::Light light;
    light.type = KIT_LIGHT_POINT;
    light.position = {x, 0.0f, 0.0f};
    scene.lights.push_back(light);
  }
  scene.lights[1].range = 5.0f;
  kit::grade::PixelInputs at;  // the origin
  std::string text = kit::grade::describe_pixel_inputs(at, scene);
  for (const char* named : {"light 2 (point, range 5 m)", "light 4 (point, no range)", "light 6 (point", "light 3 (point",
                            "and 2 more lights"})
    EXPECT_NE(text.find(named), std::string::npos) << named << " in " << text;
  for (const char* left : {"light 1 ", "light 5 "}) EXPECT_EQ(text.find(left), std::string::npos) << left << " in " << text;
  EXPECT_LT(text.find("light 2 "), text.find("light 4 ")) << text;
  kit::Light sun;
  sun.type = KIT_LIGHT_DIRECTIONAL;
  scene.lights.push_back(sun);
  text = kit::grade::describe_pixel_inputs(at, scene);
  EXPECT_LT(text.find("light 7 (directional)"), text.find("light 2 ")) << text;
  // Four or fewer: in the scene's order.
  scene.lights.resize(3);
  text = kit::grade::describe_pixel_inputs(at, scene);
  EXPECT_LT(text.find("light 1 "), text.find("light 2 ")) << text;
}
