#include "frames/lab_functions.h"

#include <nlohmann/json.hpp>

#include <glm/glm.hpp>

#include <cctype>
#include <cmath>
#include <fstream>
#include <map>
#include <utility>

#include "base/error.h"
#include "gbuffer_layout.h"
#include "render/renderer.h"  // light_flux
#include "render/stages.h"    // kit_root
#include "scene/scene.h"      // Light

namespace kit::grade {

namespace {

using json = nlohmann::json;

// A value of a case's argument as the file writes it, resolved to floats in the order the
// probe shader reads them (function_probe_inputs.glsl).
struct Reader {
  const json& sets;
  std::string where;

  [[noreturn]] void fail(const std::string& at, const std::string& why) const { throw Error(where + ": " + at + ": " + why); }

  // "$NAME" is the value of sets.NAME.
  const json& resolve(const json& v, const std::string& at) const {
    if (v.is_string()) {
      const std::string name = v.get<std::string>();
      if (name.empty() || name[0] != '$' || !sets.contains(name.substr(1)))
        fail(at, "'" + name + "' names no value of \"sets\"");
      return sets[name.substr(1)];
    }
    return v;
  }

  float number(const json& v, const std::string& at) const {
    const json& r = resolve(v, at);
    if (!r.is_number()) fail(at, "expected a number, got " + r.dump());
    return static_cast<float>(r.get<double>());
  }

  glm::vec3 triple(const json& v, const std::string& at) const {
    if (!v.is_array() || v.size() != 3) fail(at, "expected [x, y, z], got " + v.dump());
    return {number(v[0], at), number(v[1], at), number(v[2], at)};
  }

  // [x, y, z], {"direction": [theta, phi]} or {"normalize": [x, y, z]}; "below" needs the
  // case's light (`light`).
  glm::vec3 vec3(const json& value, const std::string& at, const Light* light) const {
    const json& v = resolve(value, at);
    if (v.is_array()) return triple(v, at);
    if (v.is_object() && v.size() == 1) {
      const std::string key = v.begin().key();
      const json& args = v.begin().value();
      if (key == "direction" && args.is_array() && args.size() == 2) {
        // A unit direction theta degrees from +z, turned phi degrees about z from +x.
        const float t = glm::radians(number(args[0], at)), p = glm::radians(number(args[1], at));
        return glm::vec3(std::sin(t) * std::cos(p), std::sin(t) * std::sin(p), std::cos(t));
      }
      if (key == "normalize") return glm::normalize(triple(args, at));
      if (key == "below" && args.is_array() && args.size() == 2) {
        if (!light) fail(at, "\"below\" is a point below the case's light, and this case has no Light argument before it");
        // `distance` from the light, `degrees` off the straight-down direction (toward +x).
        const float t = glm::radians(number(args[0], at)), distance = number(args[1], at);
        return light->position + distance * glm::vec3(std::sin(t), -std::cos(t), 0.0f);
      }
    }
    fail(at, "expected [x, y, z], {\"direction\": [theta, phi]}, {\"normalize\": [x, y, z]} or {\"below\": [degrees, "
             "distance]}, got " + v.dump());
  }

  Light light(const json& value, const std::string& at) const {
    const json& v = resolve(value, at);
    if (!v.is_object()) fail(at, "expected a light, got " + v.dump());
    Light l;
    const std::string type = v.value("type", std::string());
    if (type == "point") l.type = KIT_LIGHT_POINT;
    else if (type == "spot") l.type = KIT_LIGHT_SPOT;
    else if (type == "directional") l.type = KIT_LIGHT_DIRECTIONAL;
    else fail(at, "a light's \"type\" is point, spot or directional (got " + v.value("type", json()).dump() + ")");
    for (const auto& [key, field] : v.items()) {
      const std::string in = at + "." + key;
      if (key == "type") continue;
      if (key == "position") l.position = vec3(field, in, nullptr);
      else if (key == "direction") l.direction = vec3(field, in, nullptr);
      else if (key == "color") l.color = vec3(field, in, nullptr);
      else if (key == "intensity") l.intensity = number(field, in);
      else if (key == "range") l.range = number(field, in);
      else if (key == "inner_cone_degrees") l.inner_cone = glm::radians(number(field, in));
      else if (key == "outer_cone_degrees") l.outer_cone = glm::radians(number(field, in));
      else fail(in, "not a field of a light (position, direction, color, intensity, range, inner_cone_degrees, "
                    "outer_cone_degrees)");
    }
    return l;
  }
};

void append(std::vector<float>& to, glm::vec3 v) { to.insert(to.end(), {v.x, v.y, v.z}); }

// A Light as function_probe_inputs.glsl reads it (the order of lights.glsl's struct), its
// flux derived as the renderer derives it (renderer.h, light_flux).
void append(std::vector<float>& to, const Light& light) {
  to.push_back(static_cast<float>(light.type));
  append(to, light.position);
  append(to, light.direction);
  to.push_back(light.range);
  append(to, light.color);
  to.push_back(light.intensity);
  to.push_back(std::cos(light.inner_cone));
  to.push_back(std::cos(light.outer_cone));
  to.push_back(light_flux(light));
  to.push_back(0.0f);  // volume_radius: lab 7's, read by no probed function
}

ProbeType probe_type(const json& v, const std::string& at, const Reader& r) {
  const std::string name = v.is_string() ? v.get<std::string>() : "";
  if (name == "float") return ProbeType::Float;
  if (name == "vec3") return ProbeType::Vec3;
  if (name == "Light") return ProbeType::Light;
  r.fail(at, "a type is float, vec3 or Light (got " + v.dump() + ")");
}

// One block of cases: the product of its "for" loops (the first outermost), its "fixed"
// arguments the same in each.
void add_block(FunctionProbe& probe, const json& block, const std::string& at, const Reader& r) {
  if (!block.is_object()) r.fail(at, "a block of cases is an object with \"for\" and \"fixed\"");
  std::vector<std::pair<std::vector<std::string>, json>> loops;  // the argument names, the values
  if (block.contains("for")) {
    const json& list = block["for"];
    if (!list.is_array()) r.fail(at + ".for", "a list of [ARGUMENT or [ARGUMENTS], VALUES]");
    for (size_t i = 0; i < list.size(); ++i) {
      const std::string in = at + ".for[" + std::to_string(i) + "]";
      const json& loop = list[i];
      if (!loop.is_array() || loop.size() != 2) r.fail(in, "a loop is [ARGUMENT or [ARGUMENTS], VALUES]");
      std::vector<std::string> names;
      if (loop[0].is_string()) names.push_back(loop[0].get<std::string>());
      else if (loop[0].is_array())
        for (const json& n : loop[0]) names.push_back(n.is_string() ? n.get<std::string>() : "");
      const json& values = r.resolve(loop[1], in);
      if (names.empty() || !values.is_array() || values.empty()) r.fail(in, "a loop is [ARGUMENT or [ARGUMENTS], VALUES]");
      loops.emplace_back(names, values);
    }
  }
  const json fixed = block.value("fixed", json::object());
  json finite = block.value("finite_only", json());
  const json where = finite.is_object() ? finite.value("where", json()) : json();
  for (const auto& [key, value] : block.items())
    if (key != "for" && key != "fixed" && key != "finite_only")
      r.fail(at + "." + key, "a block has \"for\", \"fixed\" and \"finite_only\"");

  std::vector<size_t> index(loops.size(), 0);
  while (true) {
    // This case's value of each argument, by name.
    std::map<std::string, json> values;
    for (const auto& [name, value] : fixed.items()) values[name] = value;
    for (size_t k = 0; k < loops.size(); ++k) {
      const auto& [names, list] = loops[k];
      const json& value = list[index[k]];
      if (names.size() == 1) {
        values[names[0]] = value;
        continue;
      }
      const json& tuple = r.resolve(value, at);
      if (!tuple.is_array() || tuple.size() != names.size())
        r.fail(at, "a value of a loop over " + std::to_string(names.size()) + " arguments is a list of as many");
      for (size_t n = 0; n < names.size(); ++n) values[names[n]] = tuple[n];
    }
    ProbeCase c;
    const Light* light = nullptr;
    Light case_light;
    for (const ProbeArgument& a : probe.arguments) {
      auto it = values.find(a.name);
      if (it == values.end()) r.fail(at, "no value for the argument " + a.name + " (neither \"for\" nor \"fixed\" gives one)");
      const std::string in = at + " (" + a.name + ")";
      switch (a.type) {
        case ProbeType::Float: c.inputs.push_back(r.number(it->second, in)); break;
        case ProbeType::Vec3: append(c.inputs, r.vec3(it->second, in, light)); break;
        default:
          case_light = r.light(it->second, in);
          light = &case_light;
          append(c.inputs, case_light);
          break;
      }
    }
    if (!finite.is_null()) {
      c.finite_only = true;
      for (const auto& [name, value] : where.items())
        if (values.count(name) == 0 || r.number(values[name], at) != r.number(value, at)) c.finite_only = false;
    }
    probe.cases.push_back(c);
    if (static_cast<int>(c.inputs.size()) > 4 * kProbeTexels)
      r.fail(at, "a case holds " + std::to_string(c.inputs.size()) + " floats, more than the probe shader reads (" +
                     std::to_string(4 * kProbeTexels) + ")");
    // The next combination, the last loop fastest.
    size_t k = loops.size();
    while (k > 0 && ++index[k - 1] == loops[k - 1].second.size()) index[--k] = 0;
    if (k == 0) break;
  }
}

// "given": the functions a function calls, each with the term of the caller it is
// (function_probes.h, FunctionProbe::given).
std::map<std::string, std::string> given_functions(const json& given, const std::string& at, const Reader& r) {
  std::map<std::string, std::string> out;
  if (!given.is_object() || given.empty()) r.fail(at, "an object: each function it calls, by name, and the term it is");
  for (const auto& [function, term] : given.items()) {
    if (!term.is_string()) r.fail(at + "." + function, "the term it is (a string), got " + term.dump());
    out[function] = term.get<std::string>();
  }
  return out;
}

// A function's term probe (function_probes.h, FunctionProbe::given): its own cases, the
// function's call and uniforms (its first variant's).
FunctionProbe term_probe(const FunctionProbe& function, const json& terms, const std::string& at, const Reader& r) {
  if (!terms.is_object() || !terms.contains("id") || !terms["id"].is_string() || !terms.contains("given") ||
      !terms.contains("cases") || !terms["cases"].is_array())
    r.fail(at, "\"terms\" has \"id\", \"given\" (the functions it calls) and \"cases\"");
  for (const auto& [key, value] : terms.items())
    if (key != "id" && key != "given" && key != "why" && key != "cases")
      r.fail(at + "." + key, "\"terms\" has \"id\", \"given\", \"why\" and \"cases\"");
  FunctionProbe q = function;
  q.id = terms["id"].get<std::string>();
  q.cases.clear();
  q.given = given_functions(terms["given"], at + ".given", r);
  q.terms_only = true;
  for (size_t b = 0; b < terms["cases"].size(); ++b) add_block(q, terms["cases"][b], at + ".cases[" + std::to_string(b) + "]", r);
  return q;
}

}  // namespace

std::filesystem::path default_lab_functions_path() { return kit_root() / "tools" / "grade" / "lab_functions.json"; }

std::vector<FunctionProbe> contract_function_probes(const json& contract, int lab, const std::string& where) {
  Reader r{contract.contains("sets") ? contract["sets"] : json::object(), where};
  std::vector<FunctionProbe> probes;
  if (!contract.is_object() || !contract.contains("labs") || !contract["labs"].is_object())
    r.fail("(top)", "needs a \"labs\" object");
  const std::string key = std::to_string(lab);
  if (!contract["labs"].contains(key)) return probes;
  const json& entry = contract["labs"][key];
  const std::string at_lab = "labs." + key;
  if (!entry.is_object() || !entry.contains("shader") || !entry["shader"].is_string() || !entry.contains("functions") ||
      !entry["functions"].is_array())
    r.fail(at_lab, "a lab has \"shader\", \"includes\" and \"functions\"");
  const json& functions = entry["functions"];
  for (size_t index = 0; index < functions.size(); ++index) {
    const json& f = functions[index];
    const std::string at = at_lab + ".functions[" + std::to_string(index) + "]";
    if (!f.is_object() || !f.contains("function") || !f["function"].is_string() || !f.contains("file") ||
        !f["file"].is_string() || !f.contains("arguments") || !f["arguments"].is_array() || !f.contains("cases") ||
        !f["cases"].is_array())
      r.fail(at, "a function has \"function\", \"file\", \"arguments\", \"result\" and \"cases\"");
    FunctionProbe p;
    p.lab = lab;
    p.file = f["file"].get<std::string>();
    p.function = f["function"].get<std::string>();
    p.id = p.function;
    p.shader = entry["shader"].get<std::string>();
    p.index = static_cast<int>(index);
    p.define = "KIT_PROBE_";
    for (char c : p.function) p.define += static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
    for (size_t i = 0; i < f["arguments"].size(); ++i) {
      const json& a = f["arguments"][i];
      const std::string in = at + ".arguments[" + std::to_string(i) + "]";
      if (!a.is_array() || a.size() != 2 || !a[0].is_string()) r.fail(in, "an argument is [NAME, TYPE]");
      p.arguments.push_back({a[0].get<std::string>(), probe_type(a[1], in, r)});
    }
    p.result = probe_type(f.value("result", json()), at + ".result", r);
    // Its own probe read term by term where these agree (function_probes.h, FunctionProbe::given).
    if (f.contains("given")) p.given = given_functions(f["given"], at + ".given", r);
    if (p.result == ProbeType::Light) r.fail(at + ".result", "a result is float or vec3");
    for (size_t b = 0; b < f["cases"].size(); ++b) add_block(p, f["cases"][b], at + ".cases[" + std::to_string(b) + "]", r);
    // One probe per variant: the same cases with other uniforms set (lab 3's falloff model, gamma).
    const json variants = f.value("variants", json::array({json::object()}));
    for (size_t v = 0; v < variants.size(); ++v) {
      const json& variant = variants[v];
      const std::string in = at + ".variants[" + std::to_string(v) + "]";
      FunctionProbe q = p;
      q.id = variant.value("id", p.id);
      q.setting = variant.value("setting", std::string());
      const json uniforms = variant.value("uniforms", json::object());
      for (const auto& [name, value] : uniforms.items()) {
        ProbeUniform u{name};
        u.integer = value.is_object() && value.contains("int");
        u.value = r.number(u.integer ? value["int"] : value, in + ".uniforms." + name);
        q.uniforms.push_back(u);
      }
      probes.push_back(std::move(q));
    }
    if (f.contains("terms")) probes.push_back(term_probe(probes.back(), f["terms"], at + ".terms", r));
  }
  return probes;
}

std::vector<FunctionProbe> contract_function_probes(int lab) {
  static const std::pair<json, std::string> contract = [] {
    const std::filesystem::path path = default_lab_functions_path();
    std::ifstream in(path);
    if (!in) throw Error(path.string() + ": cannot read the labs' contract (the functions the grader probes)");
    try {
      return std::make_pair(json::parse(in), path.string());
    } catch (const json::exception& e) {
      throw Error(path.string() + ": not valid JSON (" + e.what() + ")");
    }
  }();
  return contract_function_probes(contract.first, lab, contract.second);
}

}  // namespace kit::grade
