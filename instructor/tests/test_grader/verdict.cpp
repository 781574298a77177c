// The grader's verdicts (tools/grade/verdict/): a failed lab names its likely mistake end
// to end; then the comparison criteria, called directly (kit_grade_core) on synthetic
// image pairs and checked against OpenImageIO's own statistics, grading.json's
// tolerances, the mistakes' similarity and a worst pixel's description.
#include <gtest/gtest.h>

#include <OpenImageIO/imagebufalgo.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <filesystem>
#include <map>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "frames/checks.h"
#include "gbuffer_layout.h"  // KIT_LIGHT_*
#include "grade_runs.h"
#include "images/image_io.h"
#include "kit_test.h"
#include "kit_test_files.h"
#include "render/stages.h"
#include "scene/scene.h"
#include "verdict/compare.h"
#include "verdict/config.h"
#include "verdict/diagnosis.h"
#include "verdict/lab_verdict.h"

namespace fs = std::filesystem;
using nlohmann::json;
using kit::grade::Metric;
using namespace kit::test;  // the helpers of support/ included above

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

  // kit-grade --name-again names them from each result's naming.json and the mistakes.json it
  // is given now, rendering nothing: the run graded without signatures gets the names the
  // graded run gave, to the similarity; that run's names go with the file; a lab that
  // passed has nothing to name.
  auto name_again = [](const std::vector<fs::path>& results, const std::string& extra) {
    std::string command = tool("kit-grade") + " --name-again";
    for (const fs::path& r : results) command += " " + quoted(r);
    std::string output;
    EXPECT_EQ(run(command + " " + extra, &output), 0) << output;
    return json::parse(output, nullptr, false);
  };
  const json again = name_again({without.out, r.out, correct.out}, "");
  EXPECT_EQ(again[without.out.string()]["7"], likely) << again.dump();
  EXPECT_EQ(again[r.out.string()]["7"], likely) << again.dump();
  EXPECT_EQ(again[correct.out.string()], json::object()) << again.dump();
  const json none = name_again({r.out}, "--references " + quoted(references));
  EXPECT_EQ(none[r.out.string()]["7"], json::array()) << none.dump();
  std::string output;
  EXPECT_NE(run(tool("kit-grade") + " --name-again " + quoted(sub), &output), 0) << "not a result folder: " << output;
  // Graded again into the same folder, now passing: the earlier grading's naming.json goes.
  ASSERT_TRUE(fs::exists(r.out / "naming.json"));
  EXPECT_EQ(run(tool("kit-grade") + " " + quoted(kit::kit_root() / "solutions") + " --labs 7 --jobs 2 --out " +
                    quoted(r.out), &output), 0) << output;
  EXPECT_FALSE(fs::exists(r.out / "naming.json"));
  EXPECT_EQ(name_again({r.out}, "")[r.out.string()], json::object());
}

namespace {

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

// A run finds each reference's background once (reference_background) and passes it in:
// the same covered pixels and verdict as compare_images finding it itself. The background
// is the HDR reference's top third as compared (c / (1 + c) of 0.1); the witness, a wrong
// background, counts other pixels as covered.
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
