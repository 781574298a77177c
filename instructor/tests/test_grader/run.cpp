// kit-grade end to end (tools/grade/run/): the solutions and the starters score what they
// should over a whole run, bad arguments fail, and the run's scheduler starts the labs in
// its order and renders a worker's later crashes again alone. The submissions are built
// in temp folders from copies of solutions/ and labs/, and each kit-grade run is shared by
// many assertions, so the suite stays well under two minutes.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <csignal>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "grade_runs.h"
#include "intake/sandbox.h"  // Outcome
#include "kit_test.h"
#include "render/stages.h"
#include "run/scheduler.h"

namespace fs = std::filesystem;
using nlohmann::json;
using namespace kit::test;  // the helpers of support/ included above

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
