// What kit-grade has a lab draw (tools/grade/frames/): lab 5 in a kit without its
// solution, and the checks that read other views of one frame sharing it.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <filesystem>
#include <string>

#include "grade_runs.h"
#include "kit_test.h"
#include "render/stages.h"

namespace fs = std::filesystem;
using nlohmann::json;
using namespace kit::test;  // the helpers of support/ included above

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
