// How kit-grade finds a lab's files in a submission as students really zip them
// (tools/grade/submission.*): lab folders up to kMaxWrapperDepth folders deep,
// matched case-insensitively, loose files when one lab is graded, and refusals
// that say why (too deep, loose with several labs, one lab folder in two places);
// each layout as a folder and as a zip made with the `zip` command. Then kit-grade
// itself: the folder used is in results.json, summary.json and the report, and a
// batch run again regrades the one submission whose files changed.
//
// Shipped to students: nothing here reads solutions/. The layout tests write
// their own small lab files (never rendered); the kit-grade runs copy lab 1's
// starters from labs/ (lab 1 builds on no earlier solution).
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cctype>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "intake/submission.h"
#include "kit_test.h"
#include "kit_test_files.h"
#include "render/stages.h"

namespace fs = std::filesystem;
using kit::grade::PreparedSubmission;
using kit::test::read_file;
using kit::test::write_file;
using nlohmann::json;

namespace {

std::string quoted(const fs::path& p) { return "'" + p.string() + "'"; }

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

std::string joined(const std::vector<std::string>& lines) {
  std::string out;
  for (const std::string& l : lines) out += l + "\n";
  return out;
}

// Lab `lab`'s files in `folder` (relative to `root`), each a line of GLSL naming
// where it was written, so a test can tell which copy the grader took.
void write_lab(const fs::path& root, const std::string& folder, int lab = 2) {
  for (const std::string& file : kit::find_stage(lab).files)
    write_file(root / folder / file, "// " + folder + (folder.empty() ? "" : "/") + file + "\n");
}

// `folder` zipped with the zip command (folder entries included) into `folder`.zip.
fs::path as_zip(const fs::path& folder) {
  fs::path zip = folder;
  zip += ".zip";
  fs::remove(zip);
  std::string output;
  EXPECT_EQ(kit::test::run("cd " + quoted(folder) + " && zip -q -r " + quoted(fs::absolute(zip)) + " .", &output), 0)
      << output;
  return zip;
}

// The grader's own preparation of `submission` for `labs`, in a private folder
// named after the test (ctest runs the tests of this file in parallel processes).
PreparedSubmission prepare(const fs::path& submission, const std::vector<int>& labs) {
  static int count = 0;
  std::string test = ::testing::UnitTest::GetInstance()->current_test_info()->name();
  fs::path temp = kit::test::temp_dir("layouts-prepare-" + test + "-" + std::to_string(++count));
  return kit::grade::prepare_submission(submission, labs, temp, kit::grade::Limits{});
}

// `root` as a folder and as a zip: each must give lab `lab` from `folder`, with every file.
void expect_taken_from(const fs::path& root, const std::string& folder, int lab = 2, bool loose = false) {
  const kit::Stage& stage = kit::find_stage(lab);
  for (const fs::path& submission : {root, as_zip(root)}) {
    SCOPED_TRACE(submission.string());
    PreparedSubmission p = prepare(submission, {lab});
    ASSERT_TRUE(p.problem.empty()) << p.problem;
    const kit::grade::LabFiles& files = p.labs.at(lab);
    EXPECT_TRUE(files.ready) << files.status << ": " << files.message;
    EXPECT_EQ(files.folder, folder);
    // Every expected file was copied, from that folder, under the lab's own folder name.
    for (const std::string& file : stage.files) {
      fs::path copy = p.lab_root / stage.folder / file;
      ASSERT_TRUE(fs::exists(copy)) << copy;
      std::string from = folder == "." ? file : folder + "/" + file;
      EXPECT_EQ(read_file(copy), "// " + from + "\n");
    }
    std::string where = loose ? (folder == "." ? "loose files taken from the top of the submission"
                                               : "loose files taken from '" + folder + "/'")
                              : "files taken from '" + folder + "/'";
    EXPECT_TRUE(contains(joined(p.notes), "lab " + std::to_string(lab) + " " + stage.name + ": " + where))
        << joined(p.notes);
  }
}

// `root` as a folder and as a zip: lab `lab` is refused, its message holding each of `parts`.
void expect_refused(const fs::path& root, const std::vector<int>& labs, int lab,
                    const std::vector<std::string>& parts) {
  for (const fs::path& submission : {root, as_zip(root)}) {
    SCOPED_TRACE(submission.string());
    PreparedSubmission p = prepare(submission, labs);
    ASSERT_TRUE(p.problem.empty()) << p.problem;
    const kit::grade::LabFiles& files = p.labs.at(lab);
    EXPECT_FALSE(files.ready);
    EXPECT_EQ(files.status, "invalid_files") << files.message;
    EXPECT_EQ(files.folder, "");
    for (const std::string& part : parts) EXPECT_TRUE(contains(files.message, part)) << files.message;
    EXPECT_FALSE(fs::exists(p.lab_root / kit::find_stage(lab).folder))
        << "nothing is copied for a refused layout";
  }
}

json read_json(const fs::path& path) {
  try {
    return json::parse(read_file(path));
  } catch (const std::exception&) {
    return json();
  }
}

// The first lab this kit can grade: lab 1 in the instructor's kit, a student
// copy's own lab there (its starters are in labs/, earlier labs' are not).
const kit::Stage& graded_stage() { return kit::find_stage(kit::gradable_labs().at(0)); }
std::string graded_lab() { return std::to_string(graded_stage().number); }
// Its folder name upper-cased ("01-GBUFFER"),
// as a student's file manager might leave it.
std::string shouted(std::string name) {
  for (char& c : name) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return name;
}

// That lab's starters (labs/NN-name), copied into `folder`.
void copy_starters(const fs::path& folder) {
  fs::path starters = kit::kit_root() / "labs" / graded_stage().folder;
  ASSERT_TRUE(fs::is_directory(starters)) << starters;
  fs::create_directories(folder);
  for (const std::string& file : graded_stage().files) fs::copy_file(starters / file, folder / file);
}

}  // namespace

TEST(SubmissionLayouts, LabFoldersAtTheTop) {
  fs::path root = kit::test::temp_dir("layouts-flat") / "alice";
  write_lab(root, "02-lighting");
  write_lab(root, "01-gbuffer", 1);
  expect_taken_from(root, "02-lighting");
  expect_taken_from(root, "01-gbuffer", 1);
}

TEST(SubmissionLayouts, InsideLabs) {
  fs::path root = kit::test::temp_dir("layouts-labs") / "alice";
  write_lab(root, "labs/02-lighting");
  expect_taken_from(root, "labs/02-lighting");
}

TEST(SubmissionLayouts, InsideNameAndLabs) {
  fs::path root = kit::test::temp_dir("layouts-name-labs") / "alice";
  write_lab(root, "alice/labs/02-lighting");
  expect_taken_from(root, "alice/labs/02-lighting");
}

TEST(SubmissionLayouts, InsideNameNameAndLabs) {
  fs::path root = kit::test::temp_dir("layouts-name-name-labs") / "alice";
  write_lab(root, "alice/alice/labs/02-lighting");
  expect_taken_from(root, "alice/alice/labs/02-lighting");
}

TEST(SubmissionLayouts, FourFoldersDeepIsRefusedSayingHowDeep) {
  fs::path root = kit::test::temp_dir("layouts-too-deep") / "alice";
  write_lab(root, "home/alice/alice/labs/02-lighting");
  expect_refused(root, {2}, 2, {"'home/alice/alice/labs/02-lighting/' is 4 folders deep", "at most 3 folders deep"});
}

TEST(SubmissionLayouts, LabFolderNamesInAnyCase) {
  fs::path root = kit::test::temp_dir("layouts-case") / "alice";
  write_lab(root, "Labs/02-Lighting");
  write_lab(root, "01-GBUFFER", 1);
  expect_taken_from(root, "Labs/02-Lighting");
  expect_taken_from(root, "01-GBUFFER", 1);
}

TEST(SubmissionLayouts, LooseFilesWhenOneLabIsGraded) {
  fs::path dir = kit::test::temp_dir("layouts-loose");
  write_lab(dir / "top", "");
  expect_taken_from(dir / "top", ".", 2, true);
  write_lab(dir / "wrapped", "lab2");
  expect_taken_from(dir / "wrapped", "lab2", 2, true);
  // A lab folder, when there is one, is preferred to loose files.
  write_lab(dir / "both", "");
  write_lab(dir / "both", "labs/02-lighting");
  expect_taken_from(dir / "both", "labs/02-lighting");
}

TEST(SubmissionLayouts, LooseFilesWithSeveralLabsAreRefusedSayingTheLayout) {
  fs::path dir = kit::test::temp_dir("layouts-loose-several");
  write_lab(dir / "top", "");
  expect_refused(dir / "top", {1, 2}, 2,
                 {"no 02-lighting/ folder", "'brdf.glsl'", "'lighting.frag'", "lie loose at the top of the submission",
                  "only when one lab is graded (--labs 2)", "02-lighting/lighting.frag or labs/02-lighting/lighting.frag"});
  write_lab(dir / "wrapped", "alice");
  expect_refused(dir / "wrapped", {2, 3}, 2, {"lie loose in 'alice/'", "only when one lab is graded"});
}

TEST(SubmissionLayouts, OneLabFolderInTwoPlacesIsRefusedNamingBoth) {
  fs::path root = kit::test::temp_dir("layouts-ambiguous") / "alice";
  write_lab(root, "alice/02-lighting");
  write_lab(root, "alice/old/02-Lighting");
  write_lab(root, "01-gbuffer", 1);
  expect_refused(root, {2}, 2, {"found in 2 places", "'alice/02-lighting/'", "'alice/old/02-Lighting/'"});
  // The other lab is graded as usual.
  expect_taken_from(root, "01-gbuffer", 1);
  // Loose copies in two places: refused as well.
  fs::path loose = kit::test::temp_dir("layouts-ambiguous-loose") / "bob";
  write_lab(loose, "");
  write_lab(loose, "bob");
  expect_refused(loose, {2}, 2, {"loose in 2 places", "'./'", "'bob/'"});
}

// Folders named like a lab that hold none of its files, and plain files of that name,
// give way to the folder that holds them;
// __MACOSX and hidden folders are noise wherever they are.
TEST(SubmissionLayouts, NoiseIsIgnored) {
  fs::path root = kit::test::temp_dir("layouts-noise") / "alice";
  write_lab(root, "alice/labs/02-lighting");
  write_file(root / "alice/screenshots/02-lighting/result.png", "not a lab file");
  write_file(root / "alice/notes/02-lighting", "a plain file named like the lab folder\n");
  write_lab(root, "__MACOSX/alice/labs/02-lighting");
  write_lab(root, "alice/.git/02-lighting");
  write_lab(root, ".backup/02-lighting");
  write_file(root / "alice/labs/02-lighting/helper.glsl", "// not an expected name\n");
  expect_taken_from(root, "alice/labs/02-lighting");
  PreparedSubmission p = prepare(root, {2});
  EXPECT_FALSE(fs::exists(p.lab_root / "02-lighting" / "helper.glsl")) << "only the expected names are copied";
}

// Links are never followed, at any depth: a linked lab folder is refused by name,
// a linked wrapper is not searched.
TEST(SubmissionLayouts, LinksAreNotFollowed) {
  fs::path dir = kit::test::temp_dir("layouts-links");
  write_lab(dir / "elsewhere", "02-lighting");
  fs::create_directories(dir / "linked-lab" / "alice" / "labs");
  fs::create_directory_symlink(dir / "elsewhere" / "02-lighting", dir / "linked-lab" / "alice" / "labs" / "02-lighting");
  PreparedSubmission p = prepare(dir / "linked-lab", {2});
  EXPECT_EQ(p.labs.at(2).status, "invalid_files");
  EXPECT_TRUE(contains(p.labs.at(2).message, "'alice/labs/02-lighting' is a symbolic link: refused"))
      << p.labs.at(2).message;
  fs::create_directories(dir / "linked-wrapper");
  fs::create_directory_symlink(dir / "elsewhere", dir / "linked-wrapper" / "alice");
  PreparedSubmission w = prepare(dir / "linked-wrapper", {2});
  EXPECT_EQ(w.labs.at(2).status, "missing_files");
  EXPECT_TRUE(contains(joined(w.notes), "alice (symbolic link, ignored)")) << joined(w.notes);
}

TEST(SubmissionLayouts, NothingFoundSaysWhatWasThere) {
  fs::path root = kit::test::temp_dir("layouts-nothing") / "alice";
  write_file(root / "README.txt", "hello\n");
  write_file(root / "alice/lab2/notes.txt", "hello\n");
  for (const fs::path& submission : {root, as_zip(root)}) {
    PreparedSubmission p = prepare(submission, {1, 2});
    EXPECT_EQ(p.labs.at(2).status, "missing_files");
    EXPECT_TRUE(contains(joined(p.notes), "no lab folder (01-gbuffer, 02-lighting, ...) found among: 'README.txt', 'alice/'"))
        << joined(p.notes);
  }
}

// The fingerprint a batch resumes on: the same for the same files, different
// when a file changes, blind to what the grader ignores.
TEST(SubmissionLayouts, ContentHashFollowsTheFiles) {
  fs::path root = kit::test::temp_dir("layouts-hash") / "alice";
  write_lab(root, "labs/02-lighting");
  std::string first = kit::grade::content_hash(root);
  EXPECT_EQ(first.rfind("sha1:", 0), 0u) << first;
  EXPECT_EQ(first.size(), 5u + 40u) << first;
  EXPECT_EQ(kit::grade::content_hash(root), first);
  write_file(root / ".DS_Store", "noise");
  EXPECT_EQ(kit::grade::content_hash(root), first) << "hidden entries are ignored, as the grader ignores them";
  write_file(root / "labs/02-lighting/brdf.glsl", "// changed\n");
  std::string changed = kit::grade::content_hash(root);
  EXPECT_NE(changed, first);
  fs::rename(root / "labs/02-lighting/brdf.glsl", root / "labs/02-lighting/lighting.frag.bak");
  EXPECT_NE(kit::grade::content_hash(root), changed) << "a rename changes it";
  fs::path zip = as_zip(root);
  std::string zipped = kit::grade::content_hash(zip);
  EXPECT_EQ(kit::grade::content_hash(zip), zipped);
  EXPECT_NE(zipped, kit::grade::content_hash(root));
}

// kit-grade end to end: a zip nested two folders deep with a capitalised lab
// folder; the student is told which folder was graded.
TEST(SubmissionLayouts, KitGradeReportsTheFolderUsed) {
  fs::path dir = kit::test::temp_dir("layouts-kit-grade");
  const std::string lab = graded_lab(), folder = "alice/alice/Labs/" + shouted(graded_stage().folder);
  copy_starters(dir / "alice" / folder);
  fs::path zip = as_zip(dir / "alice");
  fs::path out = dir / "out";
  std::string output;
  ASSERT_EQ(kit::test::run(kit::test::tool("kit-grade") + " " + quoted(zip) + " --labs " + lab + " --jobs 2 --out " + quoted(out),
                           &output),
            0)
      << output;
  json summary = read_json(out / "summary.json"), results = read_json(out / "results.json");
  EXPECT_EQ(summary["labs"][lab]["status"], "graded") << summary.dump(1);
  EXPECT_EQ(summary["labs"][lab]["folder"], folder);
  const std::string note = "lab " + lab + " " + graded_stage().name + ": files taken from '" + folder + "/'";
  EXPECT_TRUE(contains(summary["notes"].dump(), note)) << summary["notes"];
  EXPECT_TRUE(contains(results["output"].get<std::string>(), note)) << results["output"];
  EXPECT_TRUE(contains(read_file(out / "report.html"), "files taken from &#39;" + folder + "/&#39;"));
  EXPECT_EQ(summary["content_hash"], kit::grade::content_hash(zip));
}

// A batch run again regrades the submission whose files changed since its result
// was written, and only that one.
TEST(SubmissionLayouts, BatchResumeRegradesWhatChanged) {
  fs::path dir = kit::test::temp_dir("layouts-batch");
  fs::path in = dir / "submissions", out = dir / "results";
  const std::string lab = graded_lab(), folder = graded_stage().folder;
  copy_starters(in / "alice" / "labs" / folder);
  copy_starters(dir / "bob" / "bob" / folder);
  as_zip(dir / "bob");
  fs::rename(dir / "bob.zip", in / "bob.zip");
  const std::string command =
      kit::test::tool("kit-grade") + " --batch " + quoted(in) + " --out " + quoted(out) + " --labs " + lab + " --jobs 2";
  std::string output;
  ASSERT_EQ(kit::test::run(command, &output), 0) << output;
  EXPECT_TRUE(contains(output, "2 to grade, 0 already graded")) << output;
  for (const char* name : {"alice", "bob"}) {
    EXPECT_EQ(read_json(out / name / "summary.json")["labs"][lab]["status"], "graded") << name;
    EXPECT_EQ(read_json(out / name / "summary.json")["content_hash"].get<std::string>().size(), 45u) << name;
  }
  // A marker in each result folder: a regraded result replaces its whole folder.
  auto mark = [&](const char* name) { write_file(out / name / "marker", "kept\n"); };
  auto regraded = [&](const char* name) { return !fs::exists(out / name / "marker"); };
  mark("alice");
  mark("bob");
  auto alice_stamp = fs::last_write_time(out / "alice" / "results.json");
  auto bob_stamp = fs::last_write_time(out / "bob" / "results.json");

  // Nothing changed: nothing regraded.
  ASSERT_EQ(kit::test::run(command, &output), 0) << output;
  EXPECT_TRUE(contains(output, "0 to grade, 2 already graded")) << output;
  EXPECT_FALSE(regraded("alice"));
  EXPECT_FALSE(regraded("bob"));

  // Alice edits a file: only she is regraded, and the output says why.
  fs::path frag = in / "alice" / "labs" / folder / graded_stage().files.at(0);
  write_file(frag, read_file(frag) + "// edited after grading\n");
  ASSERT_TRUE(fs::exists(out / "alice" / "results.json")) << "the old rule (a results.json exists) would skip her";
  ASSERT_EQ(kit::test::run(command, &output), 0) << output;
  EXPECT_TRUE(contains(output, "1 to grade (1 changed since graded), 1 already graded")) << output;
  EXPECT_TRUE(contains(output, "their files changed since their results were written: alice\n")) << output;
  EXPECT_TRUE(contains(output, "[1/1] alice: ")) << output;
  EXPECT_TRUE(contains(output, "[regraded: changed]")) << output;
  EXPECT_FALSE(contains(output, "] bob: ")) << output;
  EXPECT_TRUE(regraded("alice"));
  EXPECT_NE(fs::last_write_time(out / "alice" / "results.json"), alice_stamp);
  EXPECT_FALSE(regraded("bob"));
  EXPECT_EQ(fs::last_write_time(out / "bob" / "results.json"), bob_stamp);
  EXPECT_EQ(read_json(out / "alice" / "summary.json")["content_hash"], kit::grade::content_hash(in / "alice"));

  // Bob's zip is made again with a changed file: only he is regraded.
  mark("alice");
  const fs::path bob_file = dir / "bob" / "bob" / folder / graded_stage().files.back();
  write_file(bob_file, read_file(bob_file) + "// v2\n");
  as_zip(dir / "bob");
  fs::rename(dir / "bob.zip", in / "bob.zip");
  ASSERT_EQ(kit::test::run(command, &output), 0) << output;
  EXPECT_TRUE(contains(output, "their files changed since their results were written: bob\n")) << output;
  EXPECT_TRUE(regraded("bob"));
  EXPECT_FALSE(regraded("alice"));

  // Witness: the same change against a result without a content hash (the old
  // behaviour, results.json alone) is skipped; the hash is what regrades.
  mark("alice");
  json summary = read_json(out / "alice" / "summary.json");
  summary.erase("content_hash");
  write_file(out / "alice" / "summary.json", summary.dump(1));
  write_file(frag, read_file(frag) + "// edited again\n");
  ASSERT_EQ(kit::test::run(command, &output), 0) << output;
  EXPECT_TRUE(contains(output, "0 to grade, 2 already graded")) << output;
  EXPECT_TRUE(contains(output, "1 results have no content hash")) << output;
  EXPECT_FALSE(regraded("alice")) << "without the hash the changed submission is skipped";

  // --force regrades everything, as before.
  ASSERT_EQ(kit::test::run(command + " --force", &output), 0) << output;
  EXPECT_TRUE(contains(output, "2 to grade")) << output;
  EXPECT_TRUE(regraded("alice"));
}
