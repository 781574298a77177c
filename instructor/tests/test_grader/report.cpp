// What kit-grade reports (tools/grade/report/): the report's images linked into the
// reference cache without writing through the links, its fast PNGs holding the same
// 8-bit values, and scores printed as exact sums of integer thousandths.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "frames/checks.h"
#include "grade_runs.h"
#include "images/image_io.h"
#include "kit_test.h"
#include "kit_test_files.h"
#include "render/stages.h"
#include "report/report.h"
#include "verdict/config.h"
#include "verdict/outcome.h"

namespace fs = std::filesystem;
using nlohmann::json;
using kit::grade::Metric;
using kit::grade::Thousandths;
using namespace kit::test;  // the helpers of support/ included above

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

// The report's PNGs are written fast (zlib level 1, every row Sub-filtered) and still
// hold exactly the 8-bit values the other effort writes: round to nearest, clamped.
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
  const kit::grade::Config config = kit::grade::load_config(kit::grade::default_config_path());
  for (const auto& [number, lab_points] : config.points) {
    std::vector<double> p;
    for (const auto& [key, value] : lab_points) p.push_back(value);
    expect_exact_scores(p);
    Thousandths sum = 0;
    for (const kit::grade::Check* c : kit::grade::lab_checks(number)) sum += config.max_score(*c);
    EXPECT_EQ(sum, static_cast<Thousandths>(std::llround(config.weight.at(number) * 1000))) << "lab " << number;
  }
}
