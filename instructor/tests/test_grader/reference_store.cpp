// The grader's references (tools/grade/reference_store/, and the maintenance in run/):
// decoded once into a cache that is only a cache, prepared by the build, written again
// only where their pixels changed, checked by --check-references; the G-buffers kept to
// describe a worst pixel hold the scenes; an unreadable one is its lab's error alone.
#include <gtest/gtest.h>

#include <glm/glm.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "files/files.h"
#include "frames/checks.h"
#include "grade_runs.h"
#include "images/image_io.h"
#include "kit_test.h"
#include "kit_test_files.h"
#include "reference_store/references.h"
#include "render/renderer.h"  // View
#include "render/stages.h"
#include "run/grader.h"
#include "run/options.h"
#include "verdict/compare.h"
#include "verdict/lab_verdict.h"

namespace fs = std::filesystem;
using kit::grade::Metric;
using namespace kit::test;  // the helpers of support/ included above

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
