#include "grade_runs.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include "kit_test.h"
#include "kit_test_files.h"
#include "render/stages.h"

namespace fs = std::filesystem;
using nlohmann::json;

namespace kit::test {

const int kLabCount = static_cast<int>(stages().size());

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

GradeRun grade(const fs::path& submission, const std::string& name, const std::string& extra,
               const std::string& environment) {
  GradeRun r;
  r.out = temp_dir("grader-out-" + name);
  r.exit_code = run(environment + tool("kit-grade") + " " + quoted(submission) + " --out " + quoted(r.out) + " --jobs 2 " + extra,
                    &r.output);
  r.results = read_json(r.out / "results.json");
  r.summary = read_json(r.out / "summary.json");
  return r;
}

void copy_lab(const std::string& from, int lab, const fs::path& root) {
  const std::string folder = find_stage(lab).folder;
  fs::create_directories(root / folder);
  fs::copy(kit_root() / from / folder, root / folder, fs::copy_options::recursive | fs::copy_options::overwrite_existing);
}

void edit(const fs::path& path, const std::string& find, const std::string& replace) {
  std::string text = read_file(path);
  size_t at = text.find(find);
  ASSERT_NE(at, std::string::npos) << path << " has no '" << find << "'";
  ASSERT_EQ(text.find(find, at + 1), std::string::npos) << path << " has '" << find << "' twice";
  write_file(path, text.replace(at, find.size(), replace));
}

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

namespace {

// All tests of one lab in results.json, joined (to look for a message).
std::string lab_outputs(const GradeRun& r, int number) {
  std::string prefix = "lab " + std::to_string(number) + " ", text;
  for (const json& t : r.results["tests"])
    if (t["name"].get<std::string>().rfind(prefix, 0) == 0) text += t["output"].get<std::string>() + "\n";
  return text;
}

}  // namespace

void expect_ran(const GradeRun& r) {
  EXPECT_EQ(r.exit_code, 0) << r.output;
  expect_gradescope_schema(r.results);
  EXPECT_TRUE(fs::exists(r.out / "report.html"));
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
  ASSERT_EQ(run("python3 " + quoted(zip.parent_path() / "make_zip.py") + " " + quoted(spec) + " " + quoted(zip), &output), 0)
      << output;
}

std::map<std::string, std::string> solution_entries(const std::string& prefix) {
  std::map<std::string, std::string> entries;
  for (const Stage& s : stages())
    for (const std::string& f : s.files) entries[prefix + s.folder + "/" + f] = read_file(kit_root() / "solutions" / s.folder / f);
  return entries;
}

}  // namespace kit::test
