#include "config.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <vector>

#include "error.h"
#include "stages.h"

namespace fs = std::filesystem;

namespace kit::grade {

namespace {

// Every metric the check list uses must have these fields in "tolerances".
struct RequiredFields {
  Metric metric;
  std::vector<const char*> fields;
};
const RequiredFields kRequired[] = {
    {Metric::Ldr, {"fail_threshold", "fail_percent", "hard_fail", "max_mean_error"}},
    {Metric::Hdr, {"fail_threshold", "fail_percent", "hard_fail", "max_mean_error"}},
    {Metric::Position, {"fail_threshold", "fail_percent", "hard_fail", "max_mean_error"}},
    {Metric::Normal, {"fail_threshold", "fail_percent", "hard_fail", "max_mean_error", "length_tolerance"}},
    {Metric::Albedo, {"fail_threshold", "fail_percent", "hard_fail", "max_mean_error"}},
    {Metric::Material, {"fail_threshold", "fail_percent", "hard_fail", "max_mean_error"}},
    {Metric::Changes, {"fail_threshold", "min_changed_percent"}},
};

double number(const nlohmann::json& object, const char* key, const std::string& where) {
  auto it = object.find(key);
  if (it == object.end() || !it->is_number()) throw Error(where + ": \"" + key + "\" must be a number");
  double v = it->get<double>();
  if (!(v >= 0.0)) throw Error(where + ": \"" + key + "\" must be >= 0");
  return v;
}

}  // namespace

const Tolerance& Config::tolerance(Metric metric) const {
  auto it = tolerances.find(metric_name(metric));
  if (it == tolerances.end()) throw Error(path.string() + ": no tolerance for metric " + metric_name(metric));
  return it->second;
}

double Config::lab_points(int lab) const {
  double sum = 0.0;
  auto it = points.find(lab);
  if (it != points.end())
    for (const auto& [key, p] : it->second) sum += p;
  return sum;
}

std::vector<Thousandths> apportion(Thousandths total, const std::vector<double>& points) {
  std::vector<Thousandths> shares(points.size(), 0);
  double sum = 0.0;
  for (double p : points) sum += p;
  if (sum <= 0.0 || total <= 0) return shares;
  // Exact shares floored; the thousandths the floors leave over go one each to the
  // entries with the largest remainders (ties: the earlier entry).
  std::vector<std::pair<double, size_t>> remainders;
  Thousandths given = 0;
  for (size_t i = 0; i < points.size(); ++i) {
    const double exact = static_cast<double>(total) * points[i] / sum;
    shares[i] = static_cast<Thousandths>(std::floor(exact + 1e-9));  // 2000 - 1 ulp is 2000
    given += shares[i];
    remainders.push_back({exact - static_cast<double>(shares[i]), i});
  }
  std::stable_sort(remainders.begin(), remainders.end(),
                   [](const auto& a, const auto& b) { return a.first > b.first; });
  for (size_t i = 0; given < total && i < remainders.size(); ++i, ++given) shares[remainders[i].second] += 1;
  return shares;
}

Thousandths Config::max_score(const Check& check) const {
  auto lab = points.find(check.lab);
  if (lab == points.end()) return 0;
  std::vector<double> p;
  size_t mine = 0;
  for (const auto& [key, value] : lab->second) {  // the keys' order, as results.json lists them
    if (key == check.key) mine = p.size();
    p.push_back(value);
  }
  if (!lab->second.count(check.key)) return 0;
  const Thousandths total = static_cast<Thousandths>(std::llround(weight.at(check.lab) * 1000.0));
  return apportion(total, p)[mine];
}

fs::path default_config_path() { return kit_root() / "tools" / "grade" / "grading.json"; }

Config load_config(const fs::path& path) {
  std::ifstream in(path);
  if (!in) throw Error(path.string() + ": cannot read the grading config");
  nlohmann::json doc;
  try {
    doc = nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception& e) {
    throw Error(path.string() + ": not valid JSON (" + e.what() + ")");
  }
  Config config;
  config.path = path;
  const std::string name = path.string();
  if (!doc.is_object() || !doc.contains("labs") || !doc["labs"].is_object())
    throw Error(name + ": needs a \"labs\" object");
  for (const auto& [lab_key, lab] : doc["labs"].items()) {
    int lab_number = 0;
    try {
      lab_number = find_stage(lab_key).number;
    } catch (const Error&) {
      throw Error(name + ": labs.\"" + lab_key + "\" is not a lab number (1-" + std::to_string(stages().size()) + ")");
    }
    std::string where = name + ": labs." + lab_key;
    config.weight[lab_number] = number(lab, "weight", where);
    if (!lab.contains("checks") || !lab["checks"].is_object()) throw Error(where + ": needs a \"checks\" object");
    for (const auto& [check_key, value] : lab["checks"].items()) {
      auto known = lab_checks(lab_number);
      bool exists = std::any_of(known.begin(), known.end(), [&](const Check* c) { return c->key == check_key; });
      if (!exists) throw Error(where + ".checks: unknown check \"" + check_key + "\" (tools/grade/checks.cpp lists the checks)");
      if (!value.is_number() || value.get<double>() < 0.0)
        throw Error(where + ".checks." + check_key + ": points must be a number >= 0");
      config.points[lab_number][check_key] = value.get<double>();
    }
  }
  for (const Check& c : checks()) {
    auto lab = config.points.find(c.lab);
    if (lab == config.points.end() || !lab->second.count(c.key))
      throw Error(name + ": lab " + std::to_string(c.lab) + " has no points for check \"" + c.key + "\"");
  }
  if (!doc.contains("tolerances") || !doc["tolerances"].is_object()) throw Error(name + ": needs a \"tolerances\" object");
  for (const RequiredFields& r : kRequired) {
    std::string key = metric_name(r.metric);
    if (!doc["tolerances"].contains(key)) throw Error(name + ": tolerances has no \"" + key + "\" entry");
    const nlohmann::json& t = doc["tolerances"][key];
    std::string where = name + ": tolerances." + key;
    Tolerance tol;
    for (const char* field : r.fields) {
      double v = number(t, field, where);
      std::string f = field;
      if (f == "fail_threshold") tol.fail_threshold = v;
      else if (f == "fail_percent") tol.fail_percent = v;
      else if (f == "hard_fail") tol.hard_fail = v;
      else if (f == "max_mean_error") tol.max_mean_error = v;
      else if (f == "length_tolerance") tol.length_tolerance = v;
      else if (f == "min_changed_percent") tol.min_changed_percent = v;
    }
    config.tolerances[key] = tol;
  }
  return config;
}

}  // namespace kit::grade
