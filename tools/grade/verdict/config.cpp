#include "verdict/config.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <vector>

#include "base/error.h"
#include "render/stages.h"

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
    {Metric::Same, {"fail_threshold", "fail_percent", "hard_fail", "max_mean_error"}},
    {Metric::Work, {"fail_threshold", "min_speedup"}},
};

double number(const nlohmann::json& object, const char* key, const std::string& where) {
  auto it = object.find(key);
  if (it == object.end() || !it->is_number()) throw Error(where + ": \"" + key + "\" must be a number");
  double v = it->get<double>();
  if (!(v >= 0.0)) throw Error(where + ": \"" + key + "\" must be >= 0");
  return v;
}

// Sets `field` of `tol` to `v`; false for a name that is no tolerance field.
bool set_tolerance_field(Tolerance& tol, const std::string& field, double v) {
  if (field == "fail_threshold") tol.fail_threshold = v;
  else if (field == "fail_percent") tol.fail_percent = v;
  else if (field == "hard_fail") tol.hard_fail = v;
  else if (field == "max_mean_error") tol.max_mean_error = v;
  else if (field == "length_tolerance") tol.length_tolerance = v;
  else if (field == "min_changed_percent") tol.min_changed_percent = v;
  else if (field == "min_speedup") tol.min_speedup = v;
  else return false;
  return true;
}

}  // namespace

const Tolerance& Config::tolerance(Metric metric) const {
  auto it = tolerances.find(metric_name(metric));
  if (it == tolerances.end()) throw Error(path.string() + ": no tolerance for metric " + metric_name(metric));
  return it->second;
}

// "osmesa: llvmpipe (LLVM 15.0.6, 256 bits) / 4.5 (Core Profile) Mesa 22.3.6" -> "llvmpipe, Mesa 22.3":
// GL_RENDERER's first word and the Mesa version's major.minor ("" where it is not Mesa).
std::string implementation_of(const std::string& description) {
  const size_t colon = description.find(": ");
  const size_t start = colon == std::string::npos ? 0 : colon + 2;
  const std::string renderer = description.substr(start, description.find_first_of(" /", start) - start);
  const size_t mesa = description.find("Mesa ");
  if (renderer.empty() || mesa == std::string::npos) return "";
  const size_t dot = description.find('.', mesa + 5);
  const size_t end = dot == std::string::npos ? std::string::npos : description.find_first_not_of("0123456789", dot + 1);
  return renderer + ", Mesa " + description.substr(mesa + 5, end == std::string::npos ? std::string::npos : end - mesa - 5);
}

bool Config::measured_on_renderer(const std::string& description) const {
  const std::string implementation = implementation_of(description);
  return !implementation.empty() && std::find(measured_on.begin(), measured_on.end(), implementation) != measured_on.end();
}

std::string Config::measured_on_text() const {
  std::string text;
  for (const std::string& m : measured_on) text += (text.empty() ? "" : "; ") + m;
  return text;
}

const Tolerance& Config::tolerance(const Check& check) const {
  auto it = check_tolerances.find({check.lab, check.key});
  return it != check_tolerances.end() ? it->second : tolerance(check.metric);
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
      bool exists = std::any_of(known.begin(), known.end(), [&key = check_key](const Check* c) { return c->key == key; });
      if (!exists) throw Error(where + ".checks: unknown check \"" + check_key + "\" (tools/grade/frames/checks.cpp lists the checks)");
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
    for (const char* field : r.fields) set_tolerance_field(tol, field, number(t, field, where));
    config.tolerances[key] = tol;
  }
  if (doc.contains("measured_on")) {
    if (!doc["measured_on"].is_array()) throw Error(name + ": \"measured_on\" must be a list of strings");
    for (const auto& m : doc["measured_on"]) {
      if (!m.is_string()) throw Error(name + ": \"measured_on\" must be a list of strings");
      config.measured_on.push_back(m.get<std::string>());
    }
  }
  // Each lab's own tolerances for some of its checks: the fields given replace the metric's.
  for (const auto& [lab_key, lab] : doc["labs"].items()) {
    if (!lab.contains("tolerances")) continue;
    const int lab_number = find_stage(lab_key).number;
    const std::string where = name + ": labs." + lab_key + ".tolerances";
    if (!lab["tolerances"].is_object()) throw Error(where + " must be an object");
    for (const auto& [check_key, fields] : lab["tolerances"].items()) {
      auto known = lab_checks(lab_number);
      auto check = std::find_if(known.begin(), known.end(), [&key = check_key](const Check* c) { return c->key == key; });
      if (check == known.end()) throw Error(where + ": unknown check \"" + check_key + "\"");
      if (!fields.is_object()) throw Error(where + "." + check_key + " must be an object");
      Tolerance tol = config.tolerance((*check)->metric);
      for (const auto& [field, value] : fields.items()) {
        if (field == "why") continue;  // the measurement it comes from, for people
        if (!set_tolerance_field(tol, field, number(fields, field.c_str(), where + "." + check_key)))
          throw Error(where + "." + check_key + ": unknown field \"" + field + "\"");
      }
      config.check_tolerances[{lab_number, check_key}] = tol;
    }
  }
  return config;
}

}  // namespace kit::grade
