#pragma once
// tools/grade/grading.json: what each lab is worth, the points of each of its
// checks, and the comparison tolerances per metric. Read at run time (path
// overridable with --config), so instructors change weights without rebuilding.
#include <filesystem>
#include <map>
#include <cstdint>
#include <string>
#include <vector>

#include "frames/checks.h"

namespace kit::grade {

// Scores are integer thousandths of a point, so a lab's total is the exact sum of
// its checks' shares whichever checks fail (no 4.999 from adding 1.667s).
using Thousandths = std::int64_t;

// One metric's tolerance, idiff-style: a pixel fails when any channel differs by
// more than fail_threshold; the check fails when more than fail_percent of the
// pixels fail, any pixel differs by more than hard_fail, or the mean error over
// the covered pixels is over max_mean_error (wide, faint differences).
struct Tolerance {
  double fail_threshold = 0.0;       // Normal: degrees
  double fail_percent = 0.0;         // percent of the image's pixels
  double hard_fail = 0.0;            // Normal: degrees
  double max_mean_error = 0.0;       // mean per-pixel error over the covered pixels (Normal: degrees)
  double length_tolerance = 0.0;     // Normal only: | |n| - 1 | above this fails the pixel
  double min_changed_percent = 0.0;  // Changes only: at least this share of pixels must differ
  // Work only: fail_threshold is the share by which the shaded fragments may exceed the
  // volumes' own screen coverage (rasterisers differ at the spheres' edges), and the
  // full-screen loop's work over the shaded fragments must reach min_speedup.
  double min_speedup = 0.0;
};

struct Config {
  std::filesystem::path path;
  std::map<int, double> weight;                         // lab -> its maximum score
  std::map<int, std::map<std::string, double>> points;  // lab -> check key -> points
  std::map<std::string, Tolerance> tolerances;          // metric_name() -> tolerance
  // A check's own tolerance where grading.json gives one (labs.N.tolerances.KEY: the
  // fields that differ from its metric's), for a check whose correct renders lie further
  // apart across OpenGL implementations than its metric's tolerance allows.
  std::map<std::pair<int, std::string>, Tolerance> check_tolerances;  // (lab, check key) -> tolerance

  // The OpenGL implementations the tolerances were measured on (grading.json's
  // "measured_on": renderer family and Mesa version, "llvmpipe, Mesa 22.3"): the envelope
  // in which a correct lab keeps full marks (handouts/instructors.md, Portable verdicts).
  std::vector<std::string> measured_on;
  bool measured_on_renderer(const std::string& description) const;  // a GlContext::describe() text
  std::string measured_on_text() const;                              // "llvmpipe, Mesa 22.3; ..."

  const Tolerance& tolerance(Metric metric) const;
  const Tolerance& tolerance(const Check& check) const;  // its own, else its metric's
  double lab_points(int lab) const;  // sum of the lab's check points
  // The share of the lab's weight one check is worth: weight * points / lab_points,
  // in integer thousandths of a point (the precision results.json carries),
  // apportioned once per lab so that its checks add up to exactly its weight
  // (largest remainder). Every score kit-grade adds or prints is a sum of these.
  Thousandths max_score(const Check& check) const;
};

// Largest-remainder apportionment: `total` thousandths split in proportion to
// `points`; each share is the exact share rounded down or up, and the shares add
// up to `total` exactly. Ties in the remainders go to the earlier entry.
std::vector<Thousandths> apportion(Thousandths total, const std::vector<double>& points);

// The default config: <kit root>/tools/grade/grading.json.
std::filesystem::path default_config_path();
// Reads and validates the file against the check list (every check has points,
// no unknown keys, every metric a tolerance). Throws kit::Error naming the file.
Config load_config(const std::filesystem::path& path);

}  // namespace kit::grade
