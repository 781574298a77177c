#pragma once
// kit-grade run end to end on submissions a test builds in temp folders from copies of
// solutions/ and labs/ (test_grader), and what its results.json and summary.json must hold.
#include <nlohmann/json.hpp>

#include <filesystem>
#include <map>
#include <string>

namespace kit::test {

// Every lab of the stage table (common/render/stages.cpp) is graded.
extern const int kLabCount;

// One kit-grade run: its exit status, console output, results.json, summary.json and
// the folder it wrote them to.
struct GradeRun {
  int exit_code = -1;
  std::string output;
  nlohmann::json results, summary;
  std::filesystem::path out;
};

// `p` in single quotes, for a shell command line.
std::string quoted(const std::filesystem::path& p);

// The JSON of the file `path`; null when there is none, "not valid JSON" when it does not parse.
nlohmann::json read_json(const std::filesystem::path& path);

// Runs kit-grade on `submission` into the fresh temp folder grader-out-<name> (two labs at a
// time unless `extra` says otherwise). `environment`: variables set for kit-grade alone
// ("NAME=value ").
GradeRun grade(const std::filesystem::path& submission, const std::string& name, const std::string& extra = "",
               const std::string& environment = "");

// Copies a lab folder (NN-name) of solutions/ or labs/ (`from`) into `root`.
void copy_lab(const std::string& from, int lab, const std::filesystem::path& root);

// Replaces the only occurrence of `find` in a file (fails the test when it is not there once).
void edit(const std::filesystem::path& path, const std::string& find, const std::string& replace);

// Gradescope's results.json: the keys and types its autograder reads.
void expect_gradescope_schema(const nlohmann::json& results);

// Lab `number` of the run's summary.json.
const nlohmann::json& lab(const GradeRun& r, int number);

// The run printed results.json (Gradescope's schema) and report.html, and exited 0.
void expect_ran(const GradeRun& r);
void expect_full_marks(const GradeRun& r, int number);
// Lab `number` scored zero with `status`, and its message or a check's output says `message_part`.
void expect_zero(const GradeRun& r, int number, const std::string& status, const std::string& message_part);

// Zips `entries` (name in the archive -> content) into `zip` with Python's zipfile,
// which writes any name, "../" included.
void make_zip(const std::filesystem::path& zip, const std::map<std::string, std::string>& entries);

// Every file of every lab's solution, named `prefix` + "NN-name/file" (make_zip's entries).
std::map<std::string, std::string> solution_entries(const std::string& prefix);

}  // namespace kit::test
