// kit-grade on submissions its intake refuses (tools/grade/intake/): links out of the
// submission, empty, binary, non-UTF-8 and oversized files, missing ones, an empty
// submission and zips whose entries would land outside their folder. Each scores zero
// with valid results.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "grade_runs.h"
#include "kit_test.h"
#include "kit_test_files.h"

namespace fs = std::filesystem;
using namespace kit::test;  // the helpers of support/ included above

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
