// kit-grade --batch (tools/grade/batch/): a result folder per submission, a gradebook that
// resumes, and the class summary (each check, mistake and function counted, lab 5's passes
// apart).
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <filesystem>
#include <string>

#include "grade_runs.h"
#include "kit_test.h"
#include "kit_test_files.h"

namespace fs = std::filesystem;
using nlohmann::json;
using namespace kit::test;  // the helpers of support/ included above

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
