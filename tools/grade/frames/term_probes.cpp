#include "frames/term_probes.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <functional>
#include <map>
#include <tuple>

#include "gbuffer_layout.h"  // KIT_LIGHT_*

namespace kit::grade {

namespace {

// Two ratios are the same within this (relative): a correct function written another way
// stays within 1e-5 of the expected values, every mistake the decision names moves a term
// by a few per cent at least.
constexpr double kSame = 1e-2;
bool same(double a, double b, double within = kSame) { return std::abs(a - b) <= within * std::max(std::abs(a), std::abs(b)) + 1e-9; }
// A metal's excess over the expected is a small difference of large values where the
// specular peak is high (float keeps 7 digits): the same within 5 %.
constexpr double kSameExcess = 5e-2;

// Where each argument's floats start in a case's inputs, by name.
std::map<std::string, size_t> argument_offsets(const FunctionProbe& probe) {
  std::map<std::string, size_t> at;
  size_t offset = 0;
  for (const ProbeArgument& a : probe.arguments) {
    at[a.name] = offset;
    offset += a.type == ProbeType::Float ? 1 : a.type == ProbeType::Vec3 ? 3 : a.type == ProbeType::Light ? 16 : 4;
  }
  return at;
}

// --- cook_torrance ------------------------------------------------------------------------------

// One geometry and roughness of cook_torrance's term probe, at its three materials: what the
// submission's values say of each term there.
struct CtGroup {
  glm::vec3 v, l;
  float roughness = 0.0f;
  double n_dot_l = 0.0, n_dot_v = 0.0;
  glm::dvec3 albedo{0.0};  // the metal's and the coloured dielectric's
  int metal = -1, black = -1, coloured = -1;
  double black_expected = 0.0;  // the black dielectric's expected value (the specular term at F0 = 0.04)
  double black_got = 0.0;
  double specular_black = 1.0;  // the black dielectric's value over the expected: its specular term's ratio
  glm::dvec3 specular_metal{1.0};  // the metal's value over the expected: its specular term's ratio
  glm::dvec3 metal_excess{0.0};    // the metal's value less the expected
  glm::dvec3 metal_got{0.0};
  glm::dvec3 diffuse{1.0};  // the coloured dielectric's value less the black one's, over the expected such difference
  // Whether `diffuse` says anything: not where the specular term is so much larger than the
  // diffuse lobe that float rounding of their sum hides the lobe.
  bool diffuse_known = false;
  bool l_is_v() const { return v == l; }
  std::string where() const {
    return (l_is_v() ? "at l = v, n.l = n.v = " : "with l and v either side of n, n.l = n.v = ") + probe_number(n_dot_l) +
           ", roughness " + probe_number(roughness);
  }
};

std::string triple_text(const glm::dvec3& t) {
  return "(" + probe_number(t.x) + ", " + probe_number(t.y) + ", " + probe_number(t.z) + ")";
}

bool all_same(const glm::dvec3& t, double k) { return same(t.x, k) && same(t.y, k) && same(t.z, k); }

std::vector<CtGroup> cook_torrance_groups(const FunctionProbe& probe, const std::vector<glm::vec4>& got,
                                          const std::vector<glm::vec4>& expected) {
  const std::map<std::string, size_t> at = argument_offsets(probe);
  std::vector<CtGroup> groups;
  for (size_t i = 0; i < probe.cases.size(); ++i) {
    const std::vector<float>& in = probe.cases[i].inputs;
    auto vec = [&](const char* name) { return glm::vec3(in[at.at(name)], in[at.at(name) + 1], in[at.at(name) + 2]); };
    const glm::vec3 n = vec("n"), v = vec("v"), l = vec("l"), albedo = vec("albedo");
    const float metallic = in[at.at("metallic")], roughness = in[at.at("perceptual_roughness")];
    auto g = std::find_if(groups.begin(), groups.end(),
                          [&](const CtGroup& x) { return x.v == v && x.l == l && x.roughness == roughness; });
    if (g == groups.end()) {
      g = groups.insert(groups.end(), CtGroup{v, l, roughness, glm::dot(n, l), glm::dot(n, v)});
    }
    if (metallic == 1.0f) g->metal = static_cast<int>(i);
    else if (metallic == 0.0f && albedo == glm::vec3(0.0f)) g->black = static_cast<int>(i);
    else if (metallic == 0.0f) g->coloured = static_cast<int>(i);
    if (albedo != glm::vec3(0.0f)) g->albedo = glm::dvec3(albedo);
  }
  std::vector<CtGroup> out;
  for (CtGroup& g : groups) {
    if (g.metal < 0 || g.black < 0 || g.coloured < 0) continue;
    const glm::dvec3 em(expected[g.metal]), eb(expected[g.black]), ec(expected[g.coloured]);
    const glm::dvec3 sm(got[g.metal]), sb(got[g.black]), sc(got[g.coloured]);
    if (eb.x <= 0.0 || em.x <= 0.0 || em.y <= 0.0 || em.z <= 0.0) continue;
    g.black_expected = eb.x;
    g.black_got = sb.x;
    g.specular_black = sb.x / eb.x;
    g.specular_metal = sm / em;
    g.metal_excess = sm - em;
    g.metal_got = sm;
    g.diffuse = (sc - sb) / (ec - eb);
    const double lobe = std::min(ec.x - eb.x, std::min(ec.y - eb.y, ec.z - eb.z));
    g.diffuse_known = std::max(std::abs(sb.x), eb.x) <= 100.0 * lobe;
    if (!g.diffuse_known) g.diffuse = glm::dvec3(1.0);
    out.push_back(g);
  }
  return out;
}

// The ratio k(group) in words, over the groups: "0.5 at l = v, n.l = n.v = 0.5, roughness 0.2; ...".
std::string ratios_text(const std::vector<CtGroup>& groups, const std::function<double(const CtGroup&)>& k) {
  std::string text;
  int shown = 0;
  for (const CtGroup& g : groups)
    if (!same(k(g), 1.0) && shown++ < 3) text += (text.empty() ? "" : "; ") + probe_number(k(g)) + " " + g.where();
  return text;
}

// One factor on the specular term of metal and dielectric alike, the diffuse lobe agreeing: by
// what it follows, the denominator (n.l, n.v) or the distribution (roughness).
TermDecision specular_factor(const std::vector<CtGroup>& groups) {
  const double first = groups.front().specular_black;
  bool constant = true, follows_geometry = true, follows_cosine = true, follows_square = true;
  const CtGroup* unit = nullptr;  // a group at n.l = n.v = 1
  for (const CtGroup& g : groups)
    if (same(g.n_dot_l, 1.0) && same(g.n_dot_v, 1.0)) unit = &g;
  for (const CtGroup& g : groups) {
    const double k = g.specular_black;
    constant = constant && same(k, first);
    for (const CtGroup& o : groups)
      if (o.v == g.v && o.l == g.l) follows_geometry = follows_geometry && same(o.specular_black, k);
    if (unit) {
      follows_cosine = follows_cosine && same(k, unit->specular_black * g.n_dot_l);
      follows_square = follows_square && same(k, unit->specular_black * g.n_dot_l * g.n_dot_v);
    }
  }
  if (constant)
    return {"specular-denominator", "the specular term is " + probe_number(first) +
                                        " times the expected at every input, a metal's and a dielectric's alike, and the "
                                        "diffuse lobe agrees: a constant factor in F D G / (4 (n.l)(n.v)) (its 4?)"};
  const std::string ratios = ratios_text(groups, [](const CtGroup& g) { return g.specular_black; });
  if (follows_geometry) {
    const std::string which = !unit ? ""
                              : follows_cosine ? " (it goes as n.l = n.v: one of them left out of the denominator?)"
                              : follows_square ? " (it goes as (n.l)(n.v): both left out of the denominator?)"
                                               : "";
    return {"specular-denominator", "the specular term's ratio to the expected follows n.l and n.v, not the roughness: " +
                                        ratios + "; the diffuse lobe agrees: the denominator 4 (n.l)(n.v)" + which};
  }
  return {"distribution", "the specular term's ratio to the expected changes with the roughness at the same n.l and n.v: " +
                              ratios + "; the diffuse lobe agrees: the roughness or alpha passed to D (alpha = roughness^2)"};
}

// The specular term's Fresnel factor: F0 or the angle F is taken at.
TermDecision fresnel(const std::vector<CtGroup>& groups) {
  bool black_dark = true, metal_right = true, without_f = true, metal_f0 = true, f0_right = true, lv_only_unit = true;
  bool materials_apart = false;  // a metal's specular ratio unlike a dielectric's somewhere: F's doing
  bool lv_right = true, grazing_right = true;
  double metal_k = 0.0;
  const CtGroup* off = nullptr;  // an l = v group below n.l = 1 whose specular term differs
  for (const CtGroup& g : groups) {
    materials_apart = materials_apart || !all_same(g.specular_metal, g.specular_black);
    metal_right = metal_right && all_same(g.specular_metal, 1.0);
    f0_right = f0_right && same(g.specular_black, 1.0);
    if (g.l_is_v()) {
      // At l = v, v.h = 1: F = F0 exactly, so a specular term without F is 1/F0 times the
      // expected, and a dielectric of F0 = albedo = 0 reflects nothing.
      black_dark = black_dark && std::abs(g.black_got) <= 1e-3 * g.black_expected;
      const glm::dvec3 times_albedo = g.specular_metal * g.albedo;
      without_f = without_f && same(g.specular_black, 25.0) && all_same(times_albedo, 1.0);
      if (metal_k == 0.0) metal_k = times_albedo.x;
      metal_f0 = metal_f0 && all_same(times_albedo, metal_k) && !same(metal_k, 1.0) && !all_same(g.specular_metal, 1.0);
      lv_right = lv_right && same(g.specular_black, 1.0);
      if (!same(g.specular_black, 1.0) && !same(g.n_dot_l, 1.0) && !off) off = &g;
      if (same(g.n_dot_l, 1.0)) lv_only_unit = lv_only_unit && same(g.specular_black, 1.0);
    } else {
      grazing_right = grazing_right && same(g.specular_black, 1.0);
    }
  }
  const CtGroup& unit = groups.front();
  if (black_dark && metal_right)
    return {"fresnel", "F0 is the albedo for a dielectric too (F0 = mix(0.04, albedo, metallic)): a black dielectric (albedo 0, "
                       "metallic 0) reflects nothing, where F0 = 0.04 gives " + probe_number(unit.black_expected) + " " + unit.where()};
  if (without_f)
    return {"fresnel", "the specular term is D G / (4 (n.l)(n.v)) without F: at l = v, where v.h = 1 and F = F0, it is 1/F0 "
                       "times the expected, " + probe_number(unit.specular_black) + " for a dielectric (F0 = 0.04) and " +
                       triple_text(unit.specular_metal) + " for a metal of albedo " + triple_text(unit.albedo)};
  if (f0_right && metal_f0)
    return {"fresnel", "a metal's F0 is not its albedo: at l = v, where F = F0, a metal's specular term is " +
                           triple_text(unit.specular_metal) + " times the expected (albedo " + triple_text(unit.albedo) +
                           "), as if its F0 were " + probe_number(metal_k) + "; a dielectric's agrees"};
  if (off && lv_only_unit && materials_apart)
    return {"fresnel", "F is not taken at v.h: at l = v, where v.h = 1 and F = F0 whatever n.l, the specular term agrees at "
                       "n.l = n.v = 1 but is " + probe_number(off->specular_black) + " times the expected " + off->where() +
                       " (F taken at n.l or n.v?)"};
  if (lv_right && !grazing_right && materials_apart)
    return {"fresnel", "the specular term agrees at l = v (v.h = 1, F = F0) but not where v.h is small: " +
                           ratios_text(groups, [](const CtGroup& g) { return g.specular_black; }) + ": F or v.h"};
  return {};
}

// A specular term capped at 1 (against fireflies): wherever it differs, a black dielectric's
// and a metal's value is 1.
TermDecision specular_capped(const std::vector<CtGroup>& groups) {
  const CtGroup* first = nullptr;
  for (const CtGroup& g : groups) {
    if (!same(g.specular_black, 1.0)) {
      if (!same(g.black_got, 1.0)) return {};
      if (!first) first = &g;
    }
    for (int k = 0; k < 3; ++k)
      if (!same(g.specular_metal[k], 1.0) && !same(g.metal_got[k], 1.0)) return {};
  }
  if (!first) return {};
  return {"specular-clamp", "the specular term is capped at 1: a black dielectric (its specular term alone) gives 1 " +
                                first->where() + ", where " + probe_number(first->black_expected) + " is expected"};
}

// The diffuse lobe: its (1 - F) and (1 - metallic) weights and its 1/pi.
TermDecision diffuse(const std::vector<CtGroup>& groups) {
  bool none = true, metal_lobe = true, metal_right = true, constant = true, lv_f0 = true, lv_right = true, grazing_right = true;
  const double k = groups.front().diffuse.x;
  const CtGroup* grazing = nullptr;
  bool metal_differs = false;
  for (const CtGroup& g : groups) {
    if (g.diffuse_known) none = none && all_same(g.diffuse + 1.0, 1.0);
    metal_right = metal_right && all_same(g.specular_metal, 1.0);
    metal_differs = metal_differs || !all_same(g.specular_metal, 1.0);
    // A diffuse lobe on a metal: an excess above 0 that the roughness does not change.
    for (const CtGroup& o : groups)
      if (o.v == g.v && o.l == g.l)
        for (int k = 0; k < 3; ++k)
          metal_lobe = metal_lobe && g.metal_excess[k] > 0.0 && same(o.metal_excess[k], g.metal_excess[k], kSameExcess);
    if (!g.diffuse_known) continue;
    constant = constant && all_same(g.diffuse, k);
    if (g.l_is_v()) {
      lv_f0 = lv_f0 && all_same(g.diffuse, 1.0 / 0.96);  // 1/(1 - F0): the (1 - F) weight left out
      lv_right = lv_right && all_same(g.diffuse, 1.0);
    } else {
      grazing_right = grazing_right && all_same(g.diffuse, 1.0);
      grazing = &g;
    }
  }
  const CtGroup& unit = groups.front();
  metal_lobe = metal_lobe && metal_differs;
  if (none && metal_lobe)
    return {"diffuse", "the diffuse lobe is weighted by metallic instead of (1 - metallic): a dielectric (metallic 0) has none, "
                       "a metal gets " + triple_text(unit.metal_excess) + " more than expected " + unit.where()};
  if (metal_lobe && !none)
    return {"diffuse", "a metal (metallic 1) gets a diffuse lobe, " + triple_text(unit.metal_excess) + " more than expected " +
                           unit.where() + ", the same at every roughness: the (1 - metallic) weight left out?"};
  if (!metal_right) return {};
  if (none)
    return {"diffuse", "a dielectric has no diffuse lobe: its value is its specular term alone " + unit.where()};
  if (constant)
    return {"diffuse", "the diffuse lobe is " + probe_number(k) + " times the expected at every input" +
                           (same(k, 3.14159265358979) ? " (pi): albedo / pi without the 1/pi?" : "") + "; the specular term agrees"};
  if (lv_f0 && grazing)
    return {"diffuse", "the diffuse lobe has no (1 - F) weight: at l = v, where F = F0 = 0.04, it is 1/(1 - F0) = " +
                           probe_number(unit.diffuse.x) + " times the expected, and " + probe_number(grazing->diffuse.x) +
                           " times " + grazing->where() + ", where F is larger"};
  if (lv_right && !grazing_right && grazing)
    return {"diffuse", "the diffuse lobe agrees at l = v, where F = F0, but is " + triple_text(grazing->diffuse) +
                           " times the expected " + grazing->where() + ": its (1 - F) weight is not 1 - F(v.h) (1 - F0?)"};
  return {};
}

TermDecision cook_torrance_terms(const FunctionProbe& probe, const std::vector<glm::vec4>& got,
                                 const std::vector<glm::vec4>& expected) {
  const std::vector<CtGroup> groups = cook_torrance_groups(probe, got, expected);
  if (groups.empty()) return {};
  // The whole BRDF by one factor per geometry: both terms alike.
  bool whole = true, cosine = true, any = false;
  for (const CtGroup& g : groups) {
    const double k = g.specular_black;
    whole = whole && all_same(g.specular_metal, k) && (!g.diffuse_known || all_same(g.diffuse, k));
    cosine = cosine && same(k, g.n_dot_l);
    any = any || !same(k, 1.0) || !all_same(g.specular_metal, 1.0) || !all_same(g.diffuse, 1.0);
  }
  if (!any) return {};  // every term agrees within kSame: the difference is too small to tell apart
  if (whole)
    return cosine ? TermDecision{"cosine", "the whole BRDF, diffuse and specular alike, is n.l times the expected (" +
                                               ratios_text(groups, [](const CtGroup& g) { return g.specular_black; }) +
                                               "): cook_torrance multiplies by n.l, which the reflectance equation in "
                                               "lighting.frag applies already"}
                  : TermDecision{"scale", "the whole BRDF, diffuse and specular alike, differs by one factor: " +
                                              ratios_text(groups, [](const CtGroup& g) { return g.specular_black; })};
  // One factor on the specular term of every material: not F (a metal's F0 is its albedo,
  // a dielectric's 0.04, so a mistake in F moves them apart).
  bool specular_only = true, diffuse_right = true;
  for (const CtGroup& g : groups) {
    specular_only = specular_only && all_same(g.specular_metal, g.specular_black);
    diffuse_right = diffuse_right && all_same(g.diffuse, 1.0);
  }
  if (specular_only && diffuse_right) return specular_factor(groups);
  if (TermDecision d = fresnel(groups); !d.term.empty()) return d;
  if (TermDecision d = specular_capped(groups); diffuse_right && !d.term.empty()) return d;
  if (TermDecision d = diffuse(groups); !d.term.empty()) return d;
  // No pattern fits: which terms differ, where each differs first.
  std::string text;
  bool specular = false;
  for (const CtGroup& g : groups)
    if (!same(g.specular_black, 1.0)) {
      text += "a black dielectric (its specular term alone) is " + probe_number(g.specular_black) + " times the expected " + g.where();
      specular = true;
      break;
    }
  for (const CtGroup& g : groups)
    if (!all_same(g.specular_metal, 1.0)) {
      text += (text.empty() ? "" : "; ") + std::string("a metal (no diffuse lobe) ") + triple_text(g.specular_metal) +
              " times " + g.where();
      specular = true;
      break;
    }
  for (const CtGroup& g : groups)
    if (!all_same(g.diffuse, 1.0)) {
      text += (text.empty() ? "" : "; ") + std::string("the diffuse lobe (a coloured dielectric less a black one) ") +
              triple_text(g.diffuse) + " times " + g.where();
      return {specular ? "diffuse and specular" : "diffuse", text};
    }
  return {"specular", text};
}

// --- light_radiance -----------------------------------------------------------------------------

// One case of light_radiance's probe: its light's kind, where the point lies from it, and the
// submission's value over the expected.
struct LightCase {
  std::string kind;  // "point", "spot" or "directional"
  bool ranged = false;
  double distance = 0.0, degrees = 0.0;  // from the light, off its direction (a spot's axis)
  double expected = 0.0, got = 0.0;
  double ratio() const { return got / expected; }
  std::string where() const {
    return "at " + probe_number(distance) + " from the " + (ranged ? "ranged " : "") + kind + " light" +
           (kind == "spot" ? ", " + probe_number(degrees) + " degrees off its axis" : "");
  }
};

// The cases of `kind` (ranged or not: `ranged` -1 for either) whose expected value is not 0.
std::vector<const LightCase*> lit(const std::vector<LightCase>& cases, const std::string& kind, int ranged = -1) {
  std::vector<const LightCase*> out;
  for (const LightCase& c : cases)
    if (c.kind == kind && (ranged < 0 || c.ranged == (ranged == 1)) && c.expected > 0.0) out.push_back(&c);
  return out;
}

bool all_right(const std::vector<LightCase>& cases, const std::string& kind, int ranged = -1) {
  for (const LightCase& c : cases)
    if (c.kind == kind && (ranged < 0 || c.ranged == (ranged == 1)) && !same(c.got, c.expected, kSame) &&
        std::abs(c.got - c.expected) > 1e-6)
      return false;
  return true;
}

// How the ratio to the expected goes over `cases`: "constant", "distance" (the same at each
// distance, whatever the angle), "linear" (proportional to the distance) or "".
std::string ratio_follows(const std::vector<const LightCase*>& cases) {
  if (cases.empty()) return "";
  bool constant = true, by_distance = true, linear = true;
  for (const LightCase* c : cases) {
    constant = constant && same(c->ratio(), cases.front()->ratio());
    linear = linear && same(c->ratio() / c->distance, cases.front()->ratio() / cases.front()->distance);
    for (const LightCase* o : cases)
      if (same(o->distance, c->distance, 1e-4)) by_distance = by_distance && same(o->ratio(), c->ratio());
  }
  return constant ? "constant" : linear ? "linear" : by_distance ? "distance" : "";
}

std::string ratios_text(const std::vector<const LightCase*>& cases) {
  std::string text;
  int shown = 0;
  for (const LightCase* c : cases)
    if (!same(c->ratio(), 1.0) && shown++ < 3)
      text += (text.empty() ? "" : "; ") + probe_number(c->ratio()) + " times the expected " + c->where();
  return text;
}

std::vector<LightCase> light_cases(const FunctionProbe& probe, const std::vector<glm::vec4>& got,
                                   const std::vector<glm::vec4>& expected) {
  const std::map<std::string, size_t> at = argument_offsets(probe);
  std::vector<LightCase> out;
  for (size_t i = 0; i < probe.cases.size(); ++i) {
    if (probe.cases[i].finite_only) continue;
    const float* in = probe.cases[i].inputs.data();
    const float* light = in + at.at("light");  // function_probe_inputs.glsl: type, position, direction, range, ...
    const glm::dvec3 position(light[1], light[2], light[3]), direction(light[4], light[5], light[6]);
    const glm::dvec3 p(in[at.at("p")], in[at.at("p") + 1], in[at.at("p") + 2]);
    const int type = static_cast<int>(light[0] + 0.5f);
    LightCase c;
    c.kind = type == KIT_LIGHT_SPOT ? "spot" : type == KIT_LIGHT_DIRECTIONAL ? "directional" : "point";
    c.ranged = light[7] > 0.0f;
    c.distance = glm::length(p - position);
    const double cos_off = c.distance > 0.0 ? std::clamp(glm::dot((p - position) / c.distance, direction), -1.0, 1.0) : 1.0;
    c.degrees = glm::degrees(std::acos(cos_off));
    c.expected = expected[i].x;
    c.got = got[i].x;
    out.push_back(c);
  }
  return out;
}

TermDecision light_radiance_terms(const FunctionProbe& probe, const std::vector<glm::vec4>& got,
                                  const std::vector<glm::vec4>& expected) {
  const std::vector<LightCase> cases = light_cases(probe, got, expected);
  bool simple = false;
  for (const ProbeUniform& u : probe.uniforms) simple = simple || (u.name == "u_attenuation_model" && u.value == 1.0f);
  const bool sun = all_right(cases, "directional"), point = all_right(cases, "point", 0), spot = all_right(cases, "spot", 0);
  const bool ranged = all_right(cases, "point", 1) && all_right(cases, "spot", 1);
  if (sun && point && spot && ranged) return {};  // within kSame everywhere: too small to tell apart
  if (!sun && point && spot && ranged) {
    const std::vector<const LightCase*> s = lit(cases, "directional");
    const std::string follows = ratio_follows(s);
    return {"directional", "a directional light's radiance is " + ratios_text(s) +
                               (follows == "constant" ? ""
                                                      : ": it changes with the distance from the light's node, which a "
                                                        "directional light's (its intensity the illuminance already) must not")};
  }
  if (!sun) return {};
  if (point && spot && !ranged)
    return {"range", "only lights with a range differ: " + ratios_text(lit(cases, "point", 1)) +
                         ": the glTF range window (kit_range_window)"};
  // A spot light lit outside its outer cone, where spot_cone_factor (which agrees) gives 0.
  for (const LightCase& c : cases)
    if (c.kind == "spot" && c.expected <= 0.0 && c.got > 1e-6)
      return {"spot-cone", "a spot light lights outside its outer cone: " + probe_number(c.got) + " " + c.where() +
                               ", expected 0: spot_cone_factor, which agrees, not applied?"};
  const std::vector<const LightCase*> spots = lit(cases, "spot", 0), points = lit(cases, "point", 0);
  const std::vector<const LightCase*>& off = point ? spots : points;
  const std::string follows = ratio_follows(off), kind = point ? "a spot light's" : "a point light's";
  if (follows != "constant" && follows != "linear" && follows != "distance")
    return {point ? "spot-cone" : "intensity",
            kind + " ratio to the expected changes with the angle off its axis, not only with the distance: " +
                                                   ratios_text(off)};
  if (simple && follows != "constant")
    return {"model-choice", "under the simple model (u_attenuation_model = 1), " + kind + " value is " + ratios_text(off) +
                                ": 1/(1 + d^2) not used for it?"};
  if (follows == "constant")
    return {"intensity", kind + " intensity is " + probe_number(off.front()->ratio()) + " times the expected at every point" +
                             (same(off.front()->ratio(), 4.0 * 3.14159265358979) ? " (4 pi)" : "") +
                             (point ? ": its normalisation over the cone, flux / (2 pi r^2 (1 - cos avg))?" : "")};
  return {"intensity", kind + " ratio to the expected " +
                           (follows == "linear" ? std::string("grows as the distance: it falls off as 1/r, not 1/r^2: ")
                                                : std::string("changes with the distance: ")) +
                           ratios_text(off)};
}

// --- lab 7's light_volume.frag ---------------------------------------------------------------

// A texel whose colour sums to no more than this is dark: the probes' lit texels sum to 0.03
// and more (references/probes.json), and a dark one is 0 exactly (the sphere test, a surface
// facing away).
constexpr double kDark = 1e-6;
// One factor off everywhere, but not light missing (a sphere test shading nothing is 0 times
// the expected): the catalogue's falloff at the camera is 0.0485 times it and more.
constexpr double kLeastFactor = 1e-3;

// One texel of a lab 7 probe: what the pass wrote, what it should, and the surface's
// distance from the light drawn.
struct VolumeValue {
  glm::dvec3 got, expected;
  double distance = 0.0;
  double sum(const glm::dvec3& c) const { return c.x + c.y + c.z; }
  bool lit() const { return sum(expected) > kDark; }
  double ratio() const { return sum(got) / sum(expected); }
};

std::vector<VolumeValue> volume_values(const FunctionProbe& probe, const std::vector<glm::vec4>& got,
                                       const std::vector<glm::vec4>& expected) {
  int drawn = 0;
  for (const ProbeUniform& u : probe.uniforms)
    if (u.name == "u_probe_light") drawn = static_cast<int>(u.value + 0.5f);
  const glm::dvec3 light(probe.light_volume->lights.at(static_cast<size_t>(drawn)).position);
  const size_t at = argument_offsets(probe).at("u_gbuffer_position");
  std::vector<VolumeValue> out;
  for (size_t i = 0; i < probe.cases.size(); ++i) {
    const float* p = probe.cases[i].inputs.data() + at;
    out.push_back({glm::dvec3(got[i]), glm::dvec3(expected[i]), glm::length(glm::dvec3(p[0], p[1], p[2]) - light)});
  }
  return out;
}

// Lab 7's pass differs in one of its probes (pass_probes.cpp, make_lab7): the shape of the
// difference across the probe's texels can belong to another part than the one the probe
// was set up for, since each probe holds the other parts still only where they are right.
//   each lit texel is d times the expected, d its distance from the light (not all 1 m):
//     the cosine taken with the vector to the light before it is normalised;
//   every lit texel is the same factor (not 0) off, the dark ones dark: the light's
//     strength, its falloff taken at another distance or its intensity.
TermDecision light_volume_terms(const FunctionProbe& probe, const std::vector<glm::vec4>& got,
                                const std::vector<glm::vec4>& expected) {
  const std::vector<VolumeValue> texels = volume_values(probe, got, expected);
  std::vector<const VolumeValue*> lit;
  for (const VolumeValue& t : texels) {
    if (t.lit()) lit.push_back(&t);
    else if (t.sum(t.got) > kDark) return {};  // light where there should be none: the parts' own names hold
  }
  if (lit.empty()) return {};
  bool by_distance = false, constant = lit.front()->ratio() > kLeastFactor && !same(lit.front()->ratio(), 1.0);
  for (const VolumeValue* t : lit) by_distance = by_distance || !same(t->distance, 1.0);
  std::string ratios;
  for (const VolumeValue* t : lit) {
    by_distance = by_distance && same(t->ratio(), t->distance);
    constant = constant && same(t->ratio(), lit.front()->ratio());
    if (ratios.size() < 80)
      ratios += (ratios.empty() ? "" : "; ") + probe_number(t->ratio()) + " times the expected at " + probe_number(t->distance) + " m";
  }
  if (by_distance)
    return {"cosine", "each lit texel is d times the expected, d its distance from the light (" + ratios +
                          "): n.l taken with the vector to the light before it is normalised?"};
  if (constant)
    return {"falloff", "every lit texel is " + probe_number(lit.front()->ratio()) +
                           " times the expected, whatever its material and distance: the light's strength is off by one "
                           "factor here (lab 3's falloff taken at another point, or the intensity)"};
  return {};
}

}  // namespace

TermDecision decide_terms(const FunctionProbe& probe, const std::vector<glm::vec4>& got, const std::vector<glm::vec4>& expected) {
  if (got.size() != probe.cases.size() || expected.size() != probe.cases.size()) return {};
  for (const glm::vec4& v : got)
    if (!std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z)) return {};
  if (probe.function == "cook_torrance") return cook_torrance_terms(probe, got, expected);
  if (probe.function == "light_radiance") return light_radiance_terms(probe, got, expected);
  if (probe.light_volume) return light_volume_terms(probe, got, expected);
  return {};
}

}  // namespace kit::grade
