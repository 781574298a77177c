#include "frames/function_probes.h"

#include <nlohmann/json.hpp>

#include <glm/gtc/constants.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <map>
#include <set>
#include <utility>

#include "base/error.h"
#include "frames/lab_functions.h"
#include "frames/pass_probes.h"
#include "frames/term_probes.h"
#include "gbuffer_layout.h"
#include "render/renderer.h"
#include "render/stages.h"
#include "scene/scene.h"

namespace kit::grade {

namespace {

constexpr double kPi = glm::pi<double>();
// How far a value may be from the reference solution's and still agree: relative, with a
// floor for values at 0 (relative to the probe's largest expected value). Every input is
// chosen well conditioned (no GGX peak of a near-mirror, no point on a cone's edge), so a
// correct function written another way stays within 1e-5; the smallest catalogued
// mistake a probe must see, a tone map lifted by 0.004, is 0.4 % of its largest value.
constexpr double kRelativeTolerance = 2e-3;
constexpr double kZeroTolerance = 1e-6;
// The same for a probe whose values went through an sRGB decode (FunctionProbe::srgb_decoded).
// The catalogued mistakes there (a texel decoded twice, a factor or a vertex colour left
// out) are 20 % and more.
constexpr double kSrgbRelativeTolerance = 1e-2;
constexpr double kSrgbZeroTolerance = 2e-3;
// A shape fits when every differing value fits it within this (relative).
constexpr double kShapeTolerance = 1e-2;

int components(ProbeType type) {
  switch (type) {
    case ProbeType::Float: return 1;
    case ProbeType::Vec2: return 2;
    case ProbeType::Vec3: return 3;
    case ProbeType::Vec4: return 4;
    default: return 16;
  }
}

// A float as the shortest decimal that reads back as the same float: probes.json stays
// readable ("0.1", not "0.10000000149011612") and exact.
// (Fewest digits first, up to 9, which always reads back: float std::to_chars is missing from
// the browser build's libc++.)
double short_decimal(float v) {
  if (!std::isfinite(v)) return v;
  char text[32];
  for (int digits = 1; digits <= 9; ++digits) {
    std::snprintf(text, sizeof text, "%.*g", digits, static_cast<double>(v));
    if (std::strtof(text, nullptr) == v) break;
  }
  return std::strtod(text, nullptr);
}

std::string number(double v) {
  if (std::isnan(v)) return "NaN";
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  char text[32];
  std::snprintf(text, sizeof text, "%.4g", v);
  return text;
}

std::string vec3_text(const float* v) { return "(" + number(v[0]) + ", " + number(v[1]) + ", " + number(v[2]) + ")"; }

// An input as a student would write it: a direction's 0 made from sin(180 degrees) is
// -4.4e-08 in float, shown as 0.
double input(float v) { return std::abs(v) < 1e-6f ? 0.0 : v; }
std::string input_vector_text(const float* v, int n) {
  std::string text = "(";
  for (int i = 0; i < n; ++i) text += (i ? ", " : "") + number(input(v[i]));
  return text + ")";
}
std::string input_vec3_text(const float* v) { return input_vector_text(v, 3); }

std::string light_text(const float* v) {
  const int type = static_cast<int>(v[0] + 0.5f);
  std::string text = type == KIT_LIGHT_SPOT ? "spot light" : type == KIT_LIGHT_DIRECTIONAL ? "directional light" : "point light";
  text += type == KIT_LIGHT_DIRECTIONAL ? " (" : " at " + input_vec3_text(v + 1) + " (";
  if (type != KIT_LIGHT_POINT) text += "direction " + input_vec3_text(v + 4) + ", ";
  text += "intensity " + number(v[11]);
  if (v[7] > 0.0f) text += ", range " + number(v[7]);
  if (type == KIT_LIGHT_SPOT) text += ", cos_inner " + number(v[12]) + ", cos_outer " + number(v[13]);
  return text + ")";
}

std::string call_text(const FunctionProbe& probe, size_t index) {
  const ProbeCase& c = probe.cases[index];
  // A pass: where it writes, with what its samplers hold there ("bright.frag at texel 3 (u_hdr = ...)").
  std::string text = probe.pass ? probe.file + " at texel " + std::to_string(index) + " (" : probe.function + "(";
  const float* at = c.inputs.data();
  for (size_t i = 0; i < probe.arguments.size(); ++i) {
    const ProbeArgument& a = probe.arguments[i];
    text += (i ? ", " : "") + a.name + " = ";
    text += a.type == ProbeType::Float ? number(input(*at)) : a.type == ProbeType::Light ? light_text(at) : input_vector_text(at, components(a.type));
    at += components(a.type);
  }
  return text + ")";
}

std::string value_text(const FunctionProbe& probe, const glm::vec4& v) {
  return probe.result == ProbeType::Float ? number(v.x) : vec3_text(&v.x);
}

bool finite(const FunctionProbe& probe, const glm::vec4& v) {
  for (int i = 0; i < components(probe.result); ++i)
    if (!std::isfinite(v[i])) return false;
  return true;
}

// A constant factor, by its name where it is a usual one.
std::string factor_text(double k) {
  if (std::abs(k + 1.0) <= kShapeTolerance) return "each of the opposite sign";
  if (std::abs(k) <= kShapeTolerance) return "0 at each of them";
  const std::pair<double, const char*> named[] = {
      {kPi, "pi"},          {1.0 / kPi, "1/pi"},          {0.5, "1/2"},       {0.25, "1/4"},
      {4.0 * kPi, "4 pi"}, {1.0 / (4.0 * kPi), "1/(4 pi)"}, {2.0 * kPi, "2 pi"}, {1.0 / (2.0 * kPi), "1/(2 pi)"}};
  std::string text = "each by a factor of " + number(k);
  for (const auto& [value, name] : named)
    if (std::abs(k - value) <= kShapeTolerance * value) return text + " (" + name + ")";
  return text;
}

bool near(double a, double b) { return std::abs(a - b) <= kShapeTolerance * std::max(std::abs(a), std::abs(b)) + 1e-12; }

// A probe's differing cases (compare_probe), for the shape of the difference.
struct Differences {
  const FunctionProbe& probe;
  const ProbeValues& got;
  const std::vector<glm::vec4>& expected;
  const std::vector<size_t>& cases;  // the differing cases
  const std::vector<bool>& differs;  // by case
  int non_finite;                    // differing cases whose value is not finite
  int components;                    // of the result
  double zero;                       // an expected value within this of 0 counts as 0
};

// The same factor, offset, square or square root in every differing value compared.
std::string value_shape(const Differences& d) {
  const FunctionProbe& probe = d.probe;
  std::vector<std::pair<double, double>> pairs;  // (got, expected) per component
  for (size_t i : d.cases)
    if (!probe.cases[i].finite_only && finite(probe, d.got.values[i]))
      for (int k = 0; k < d.components; ++k)
        if (std::abs(d.expected[i][k]) > d.zero) pairs.emplace_back(d.got.values[i][k], d.expected[i][k]);
  auto all_pairs = [&](auto fits) {
    if (pairs.empty()) return false;
    for (const auto& [s, e] : pairs)
      if (!fits(s, e)) return false;
    return true;
  };
  if (static_cast<size_t>(d.non_finite) == d.cases.size()) {
    return "each not a number or infinite (a denominator reaching 0 without a guard?)";
  } else if (const double k = pairs.empty() ? 1.0 : pairs.front().first / pairs.front().second;
             !pairs.empty() && std::abs(k - 1.0) > kShapeTolerance && all_pairs([&](double s, double e) { return near(s / e, k); })) {
    return factor_text(k);
  } else if (const double offset = pairs.empty() ? 0.0 : pairs.front().first - pairs.front().second;
             !pairs.empty() && all_pairs([&](double s, double e) { return near(s - e, offset); })) {
    return std::string("each ") + (offset > 0 ? "higher" : "lower") + " by " + number(std::abs(offset));
  } else if (all_pairs([](double s, double e) { return near(s, e * e); })) {
    return "each the square of the expected value";
  } else if (all_pairs([](double s, double e) { return e > 0 && near(s, std::sqrt(e)); })) {
    return "each the square root of the expected value";
  }
  return "";
}

// Two scalar arguments swapped: each differing value is the expected one at the case with
// those two arguments exchanged.
std::string swapped_arguments_shape(const Differences& d) {
  const FunctionProbe& probe = d.probe;
  std::vector<int> offsets;
  int at = 0;
  for (const ProbeArgument& a : probe.arguments) {
    offsets.push_back(a.type == ProbeType::Float ? at : -1);
    at += components(a.type);
  }
  for (size_t a = 0; a < offsets.size(); ++a)
    for (size_t b = a + 1; b < offsets.size(); ++b) {
      if (offsets[a] < 0 || offsets[b] < 0) continue;
      bool fits = true;
      for (size_t i : d.cases) {
        std::vector<float> swapped = probe.cases[i].inputs;
        std::swap(swapped[offsets[a]], swapped[offsets[b]]);
        auto j = std::find_if(probe.cases.begin(), probe.cases.end(), [&](const ProbeCase& c) { return c.inputs == swapped; });
        if (j == probe.cases.end() || probe.cases[i].finite_only || !finite(probe, d.got.values[i])) {
          fits = false;
          break;
        }
        const glm::vec4& e = d.expected[static_cast<size_t>(j - probe.cases.begin())];
        for (int k = 0; k < d.components; ++k) fits = fits && near(d.got.values[i][k], e[k]);
      }
      if (fits) return probe.arguments[a].name + " and " + probe.arguments[b].name + " swapped";
    }
  return "";
}

// Only where a scalar argument is 0 or 1 (an edge of its range): every case with no
// argument at an edge agrees, and there are such cases.
std::string edge_shape(const Differences& d) {
  const FunctionProbe& probe = d.probe;
  auto at_edge = [&](const ProbeCase& c) {
    int at = 0;
    bool edge = false;
    for (const ProbeArgument& a : probe.arguments) {
      if (a.type == ProbeType::Float) edge = edge || c.inputs[at] == 0.0f || c.inputs[at] == 1.0f;
      at += components(a.type);
    }
    return edge;
  };
  bool inner_cases = false, inner_agree = true;
  for (size_t i = 0; i < probe.cases.size(); ++i)
    if (!at_edge(probe.cases[i])) {
      inner_cases = true;
      inner_agree = inner_agree && !d.differs[i];
    }
  return !probe.pass && inner_cases && inner_agree ? "only where an argument is 0 or 1" : "";
}

// The shape of the difference over the differing values, in words; "" where none fits.
std::string difference_shape(const Differences& d) {
  std::string shape = value_shape(d);
  if (shape.empty()) shape = swapped_arguments_shape(d);
  if (shape.empty()) shape = edge_shape(d);
  return shape;
}

}  // namespace

std::string probe_number(double v) { return number(v); }

std::string FunctionProbe::title() const {
  const std::string& name = pass ? file : function;
  return setting.empty() ? name : name + " (" + setting + ")";
}

std::string FunctionProbe::part() const { return !pass ? function : term.empty() ? file : file + ", " + term; }

const std::vector<FunctionProbe>& function_probes(int lab) {
  // Each lab's made on first use, so that grading one lab reads only what it needs: labs 2
  // and 3's functions come from their contract (tools/grade/lab_functions.json), whose
  // error then costs those labs alone; the passes' set-ups (labs 1, 4, 5, 6 and 7) are
  // pass_probes.h's.
  static const std::vector<FunctionProbe> none;
  switch (lab) {
    case 1: { static const std::vector<FunctionProbe> probes = pass_probes(1); return probes; }
    case 2: { static const std::vector<FunctionProbe> probes = contract_function_probes(2); return probes; }
    case 3: { static const std::vector<FunctionProbe> probes = contract_function_probes(3); return probes; }
    case 4: { static const std::vector<FunctionProbe> probes = pass_probes(4); return probes; }
    case 5: { static const std::vector<FunctionProbe> probes = pass_probes(5); return probes; }
    case 6: { static const std::vector<FunctionProbe> probes = pass_probes(6); return probes; }
    case 7: { static const std::vector<FunctionProbe> probes = pass_probes(7); return probes; }
    default: return none;
  }
}

const std::vector<FunctionProbe>& all_function_probes() {
  static const std::vector<FunctionProbe> all = [] {
    std::vector<FunctionProbe> out;
    for (const Stage& stage : stages())
      out.insert(out.end(), function_probes(stage.number).begin(), function_probes(stage.number).end());
    return out;
  }();
  return all;
}

nlohmann::json probe_values_json(const ProbeValues& values) {
  nlohmann::json out = nlohmann::json::object();
  if (!values.error.empty()) out["error"] = values.error;
  nlohmann::json list = nlohmann::json::array();
  for (const glm::vec4& v : values.values) list.push_back({v.x, v.y, v.z, v.w});
  out["values"] = list;
  return out;
}

namespace {

// JSON has no NaN or infinity: nlohmann writes null, read back as NaN.
float json_float(const nlohmann::json& v) { return v.is_number() ? v.get<float>() : std::nanf(""); }

}  // namespace

ProbeValues probe_values_from_json(const nlohmann::json& json) {
  ProbeValues out;
  if (!json.is_object()) return out;
  out.error = json.value("error", std::string());
  if (json.contains("values") && json["values"].is_array())
    for (const auto& v : json["values"])
      if (v.is_array() && v.size() == 4)
        out.values.emplace_back(json_float(v[0]), json_float(v[1]), json_float(v[2]), json_float(v[3]));
  return out;
}

nlohmann::json probes_reference_json(const std::vector<std::pair<const FunctionProbe*, ProbeValues>>& expected) {
  nlohmann::json probes = nlohmann::json::object();
  for (const auto& [probe, values] : expected) {
    nlohmann::json cases = nlohmann::json::array();
    for (size_t i = 0; i < probe->cases.size(); ++i) {
      nlohmann::json in = nlohmann::json::array(), out = nlohmann::json::array();
      for (float v : probe->cases[i].inputs) in.push_back(short_decimal(v));
      for (int k = 0; k < components(probe->result); ++k) out.push_back(short_decimal(values.values.at(i)[k]));
      nlohmann::json c = {{"in", in}, {"expected", out}};
      if (probe->cases[i].finite_only) c["finite_only"] = true;
      cases.push_back(c);
    }
    nlohmann::json arguments = nlohmann::json::array();
    for (const ProbeArgument& a : probe->arguments) arguments.push_back(a.name);
    probes[probe->id] = {{"lab", probe->lab}, {"file", probe->file}, {"function", probe->function},
                         {"arguments", arguments}, {"cases", cases}};
    if (!probe->setting.empty()) probes[probe->id]["setting"] = probe->setting;
  }
  return {{"about", "The reference solutions' values of the probed lab functions at fixed inputs "
                    "(tools/grade/function_probes.h); kit-grade --update-references writes them."},
          {"probes", probes}};
}

namespace {

// The stored cases of `probe`, when they are as many as the table's and each has as many
// inputs and expected values; else null.
const nlohmann::json* stored_cases(const nlohmann::json& reference, const FunctionProbe& probe) {
  if (!reference.is_object() || !reference.contains("probes") || !reference["probes"].is_object() ||
      !reference["probes"].contains(probe.id))
    return nullptr;
  const nlohmann::json& stored = reference["probes"][probe.id];
  if (!stored.is_object() || !stored.contains("cases") || !stored["cases"].is_array()) return nullptr;
  const nlohmann::json& cases = stored["cases"];
  if (cases.size() != probe.cases.size()) return nullptr;
  for (size_t i = 0; i < cases.size(); ++i) {
    const nlohmann::json& c = cases[i];
    if (!c.is_object() || !c.contains("in") || !c.contains("expected") || !c["in"].is_array() ||
        !c["expected"].is_array() || c["in"].size() != probe.cases[i].inputs.size() ||
        c["expected"].size() != static_cast<size_t>(components(probe.result)))
      return nullptr;
  }
  return &cases;
}

// Inputs equal but for float rounding (sin and cos differ in their last bit between libms).
bool same_input(float a, float b) { return std::abs(a - b) <= 1e-5f * std::max(1.0f, std::max(std::abs(a), std::abs(b))); }

}  // namespace

std::vector<FunctionProbe> probes_to_run(int lab, const nlohmann::json& reference) {
  std::vector<FunctionProbe> out = function_probes(lab);
  for (FunctionProbe& probe : out)
    if (const nlohmann::json* cases = stored_cases(reference, probe))
      for (size_t i = 0; i < cases->size(); ++i)
        for (size_t k = 0; k < probe.cases[i].inputs.size(); ++k)
          probe.cases[i].inputs[k] = json_float((*cases)[i]["in"][k]);
  return out;
}

std::vector<glm::vec4> expected_probe_values(const nlohmann::json& reference, const FunctionProbe& probe) {
  std::vector<glm::vec4> out;
  const nlohmann::json* stored = stored_cases(reference, probe);
  if (!stored) return out;
  const nlohmann::json& cases = *stored;
  for (size_t i = 0; i < cases.size(); ++i) {
    const nlohmann::json& in = cases[i]["in"];
    const nlohmann::json& expected = cases[i]["expected"];
    for (size_t k = 0; k < in.size(); ++k)
      if (!same_input(json_float(in[k]), probe.cases[i].inputs[k])) return {};
    glm::vec4 v(0.0f);
    for (size_t k = 0; k < expected.size(); ++k) v[static_cast<int>(k)] = json_float(expected[k]);
    out.push_back(v);
  }
  return out;
}

std::vector<std::string> probes_reference_differences(const nlohmann::json& reference) {
  std::vector<std::string> out;
  for (const FunctionProbe& probe : all_function_probes())
    if (expected_probe_values(reference, probe).empty())
      out.push_back("probes.json: " + probe.id + " is missing or has other inputs than the probe table");
  if (reference.is_object() && reference.contains("probes"))
    for (const auto& [id, value] : reference["probes"].items()) {
      bool known = false;
      for (const FunctionProbe& probe : all_function_probes()) known = known || probe.id == id;
      if (!known) out.push_back("probes.json: " + id + " is no longer probed");
    }
  return out;
}

ProbeOutcome compare_probe(const FunctionProbe& probe, const ProbeValues& got, const std::vector<glm::vec4>& expected) {
  ProbeOutcome o;
  // The table's own probe (it outlives the outcome); `probe`'s inputs may be probes.json's.
  o.probe = &probe;
  for (const FunctionProbe& p : function_probes(probe.lab))
    if (p.id == probe.id) o.probe = &p;
  o.part = probe.part();
  o.total = static_cast<int>(probe.cases.size());
  if (!got.error.empty() || got.values.size() != probe.cases.size() || expected.size() != probe.cases.size()) {
    o.status = kProbeNotRun;
    o.message = probe.title() + ": not probed (" +
                (!got.error.empty() ? got.error
                 : expected.size() != probe.cases.size() ? std::string("no expected values in the references")
                                                          : std::string("no values")) +
                ")";
    return o;
  }
  const int n = components(probe.result);
  double scale = 0.0;
  for (const glm::vec4& e : expected)
    for (int k = 0; k < n; ++k)
      if (std::isfinite(e[k])) scale = std::max(scale, static_cast<double>(std::abs(e[k])));
  const double relative = probe.srgb_decoded ? kSrgbRelativeTolerance : kRelativeTolerance;
  const double zero = (probe.srgb_decoded ? kSrgbZeroTolerance : kZeroTolerance) * std::max(1.0, scale);
  std::vector<size_t> differing;
  std::vector<bool> differs(probe.cases.size(), false);
  int non_finite = 0;
  for (size_t i = 0; i < probe.cases.size(); ++i) {
    const glm::vec4& s = got.values[i];
    const glm::vec4& e = expected[i];
    bool bad = !finite(probe, s);
    if (!bad && !probe.cases[i].finite_only)
      for (int k = 0; k < n; ++k) {
        const double tolerance = relative * std::max(std::abs(s[k]), std::abs(e[k])) + zero;
        bad = bad || std::abs(static_cast<double>(s[k]) - e[k]) > tolerance;
      }
    if (bad) {
      differing.push_back(i);
      differs[i] = true;
      if (!finite(probe, s)) ++non_finite;
    }
  }
  o.differing = static_cast<int>(differing.size());
  if (differing.empty()) {
    o.status = kProbeAgrees;
    o.message = probe.title() + ": agrees at all " + std::to_string(o.total) + (probe.pass ? " texels" : " inputs");
    return o;
  }
  o.status = kProbeDiffers;
  const size_t first = differing.front();
  o.first = call_text(probe, first) + (probe.pass ? " writes " : " = ") + value_text(probe, got.values[first]) +
            (probe.cases[first].finite_only ? ", expected a finite value" : ", expected " + value_text(probe, expected[first]));

  o.shape = difference_shape({probe, got, expected, differing, differs, non_finite, n, zero});
  o.message = o.first + "; " + std::to_string(o.differing) + " of " + std::to_string(o.total) + (probe.pass ? " texels differ" : " inputs differ") +
              (o.shape.empty() ? "" : ", " + o.shape);
  if (!probe.setting.empty()) o.message += " (" + probe.setting + ")";
  return o;
}

nlohmann::json probe_outcome_json(const ProbeOutcome& o) {
  nlohmann::json out = {{"id", o.probe->id},     {"function", o.probe->function}, {"file", o.probe->file},
                        {"part", o.part},
                        {"status", o.status},    {"differing", o.differing},      {"total", o.total},
                        {"message", o.message}};
  if (!o.probe->setting.empty()) out["setting"] = o.probe->setting;
  if (!o.first.empty()) out["first"] = o.first;
  if (!o.shape.empty()) out["shape"] = o.shape;
  return out;
}

nlohmann::json read_probes_reference(const std::filesystem::path& dir) {
  std::ifstream in(dir / "probes.json");
  if (!in) return nullptr;
  try {
    return nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception&) {
    return nullptr;  // the probes say so ("no expected values"); the images do not depend on it
  }
}

std::vector<std::string> write_probes_reference(const std::filesystem::path& dir, const nlohmann::json& probes) {
  // One line per case, so that a change to one function's values is a diff of its lines.
  std::string text = "{\n  \"about\": " + probes.value("about", nlohmann::json("")).dump() + ",\n  \"probes\": {";
  bool first = true;
  const nlohmann::json listed = probes.value("probes", nlohmann::json::object());
  for (const auto& [id, probe] : listed.items()) {
    text += std::string(first ? "" : ",") + "\n    " + nlohmann::json(id).dump() + ": {";
    first = false;
    for (const auto& [key, value] : probe.items())
      if (key != "cases") text += nlohmann::json(key).dump() + ": " + value.dump() + ", ";
    text += "\"cases\": [";
    const nlohmann::json cases = probe.value("cases", nlohmann::json::array());
    for (size_t i = 0; i < cases.size(); ++i) text += std::string(i ? "," : "") + "\n      " + cases[i].dump();
    text += "\n    ]}";
  }
  text += "\n  }\n}\n";
  const std::filesystem::path path = dir / "probes.json";
  std::ifstream old(path, std::ios::binary);
  if (old && std::string(std::istreambuf_iterator<char>(old), {}) == text) return {};
  std::ofstream out(path, std::ios::binary);
  out << text;
  if (!out) throw Error(path.string() + ": cannot write");
  return {"probes.json"};
}

namespace {

// A term probe that differs (FunctionProbe::given): explained by a function it calls that
// differs, else its terms told apart where the decision fits (term_probes.h). A lab 7 probe
// that differs: its part where the difference's shape places it (term_probes.h).
void read_terms(ProbeOutcome& o, const std::vector<ProbeOutcome>& all, const std::vector<glm::vec4>& got,
                const std::vector<glm::vec4>& expected) {
  if (o.status != kProbeDiffers) return;
  if (o.probe->light_volume) {  // lab 7's pass: the difference's shape may place it in another part
    const TermDecision d = decide_terms(*o.probe, got, expected);
    if (d.term.empty()) return;
    o.part = o.probe->file + ", " + d.term;
    o.message += "; by its shape: " + d.text;
    return;
  }
  std::string explained;
  std::set<std::string> terms;  // of the given functions that differ
  for (const ProbeOutcome& g : all)
    if (g.probe->given.empty() && g.status != kProbeAgrees && o.probe->given.count(g.probe->function) &&
        explained.find(g.probe->function) == std::string::npos) {
      explained += (explained.empty() ? "" : ", ") + g.probe->function;
      terms.insert(o.probe->given.at(g.probe->function));
    }
  if (!explained.empty()) {
    // One function that differs places the difference in its term, as a decision would.
    if (terms.size() == 1) o.part = o.probe->function + ", " + *terms.begin();
    if (!o.probe->terms_only) return;  // the function's own probe says where it differs
    o.status = kProbeExplained;
    o.message = o.probe->title() + ": its terms are not told apart where a function it calls differs (" + explained + ")";
    return;
  }
  const TermDecision d = decide_terms(*o.probe, got, expected);
  if (d.term.empty()) return;
  o.part = o.probe->function + ", " + d.term;
  const std::string setting = o.probe->setting.empty() ? "" : " (" + o.probe->setting + ")";
  o.message = o.probe->terms_only ? o.probe->function + ", term by term: " + d.text + setting
                                  : o.message + "; term by term: " + d.text;
}

}  // namespace

std::vector<ProbeOutcome> probe_outcomes(int lab, const nlohmann::json& child, const nlohmann::json& reference) {
  std::vector<ProbeOutcome> out;
  const nlohmann::json got = child.is_object() ? child.value("probes", nlohmann::json::object()) : nlohmann::json::object();
  const std::string error = child.is_object() ? child.value("probes_error", std::string()) : std::string();
  std::vector<ProbeValues> got_values;
  std::vector<std::vector<glm::vec4>> expected_values;
  for (const FunctionProbe& probe : probes_to_run(lab, reference)) {
    ProbeValues values = probe_values_from_json(got.value(probe.id, nlohmann::json()));
    if (!error.empty()) values.error = error;
    else if (!got.contains(probe.id)) values.error = "the renderer did not probe it";
    expected_values.push_back(expected_probe_values(reference, probe));
    out.push_back(compare_probe(probe, values, expected_values.back()));
    got_values.push_back(std::move(values));
  }
  for (size_t i = 0; i < out.size(); ++i)
    if (!out[i].probe->given.empty() || out[i].probe->light_volume)
      read_terms(out[i], out, got_values[i].values, expected_values[i]);
  return out;
}

std::vector<std::string> probe_feedback(const std::vector<ProbeOutcome>& probes, bool a_check_failed) {
  std::vector<std::string> out;
  int agree = 0;
  for (const ProbeOutcome& p : probes) {
    if (p.status == kProbeDiffers) out.push_back((p.probe->pass ? "Your pass " : "Your function ") + p.message);
    agree += p.status == kProbeAgrees;
  }
  if (out.empty() && a_check_failed && agree > 0 && agree == static_cast<int>(probes.size())) {
    std::string files;
    for (const ProbeOutcome& p : probes)
      if (files.find(p.probe->file) == std::string::npos) files += (files.empty() ? "" : " and ") + p.probe->file;
    if (probes.front().probe->file == "light_volume.frag")
      out.push_back("light_volume.frag, drawn alone for one light, writes what the reference solution's does at every "
                    "probed texel: look for the mistake in light_volume.vert (where the volume is placed, its radius, "
                    "the pragma's state).");
    else if (probes.front().probe->pass)
      out.push_back("Each of " + files + ", drawn alone, writes what the reference solution's does at every "
                    "probed texel: look for the mistake elsewhere (custom_effect.frag, or a setting the probes do not draw).");
    else
      out.push_back("Every probed function of " + files + " agrees with the reference solution's at all its inputs: "
                    "look for the mistake where they are called.");
  }
  return out;
}

}  // namespace kit::grade
