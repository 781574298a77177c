// The grader's function probes (tools/grade/frames/function_probes.h):
//   * the expected values in tools/grade/references/probes.json, made on the GPU path from
//     the reference solutions, agree with the CPU reference in double precision
//     (instructor/reference/cpu_reference.h), at every input; witness: a CPU GGX without
//     its pi disagrees;
//   * the probe pass on lab files with a planted mistake names the function, its first
//     differing inputs and the shape of the difference (a factor of pi, swapped arguments),
//     and a lab that renamed a function loses only that function's probe.
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <map>
#include <sstream>
#include <set>
#include <string>
#include <vector>

#include "base/error.h"
#include "cpu_reference.h"
#include "frames/function_probes.h"
#include "frames/lab_functions.h"
#include "frames/probe_pass.h"
#include "gbuffer_layout.h"
#include "ibl_reference.h"
#include "images/texture_prepare.h"  // srgb_to_linear
#include "kit_test.h"
#include "reference_store/references.h"
#include "render/stages.h"

namespace kit::test {
namespace {

namespace ref = kit::reference;
using grade::FunctionProbe;
using grade::ProbeType;

// GPU float against the CPU's double. The worst input is the GGX peak of the smoothest
// material probed (alpha = 0.04, n.h = 1), where d = (n.h)^2 (alpha^2 - 1) + 1 cancels to
// alpha^2 in float and loses 1.4e-4 (test_lab_equations.cpp, kMinHdrAgreement, says more);
// the catalogued mistakes are 1e-2 and more.
constexpr double kCpuRelativeTolerance = 5e-4;
// Values through an 8-bit sRGB decode, which GL lets an implementation approximate
// (FunctionProbe::srgb_decoded): llvmpipe's is 0.17 % low at 200/255.
constexpr double kCpuSrgbTolerance = 1e-2;

nlohmann::json probes_reference() { return grade::read_probes_reference(grade::default_references_dir()); }

// Reads a probe case's arguments in order (cpu_reference.h).
using Arguments = ref::ProbeArguments;

// A pass probe's texel as the G-buffer holds it: position, normal, albedo, (metallic, roughness).
ref::SurfaceSample texel_sample(const std::vector<float>& inputs) {
  Arguments a{inputs};
  ref::SurfaceSample s;
  s.position = a.vec3();
  s.normal = a.vec3();
  s.albedo = a.vec3();
  const ref::dvec3 material = a.vec3();
  s.metallic = material.x;
  s.roughness = material.y;
  s.covered = true;
  return s;
}

// A function probe's value from the CPU reference: the function of that name in the contract's
// table (cpu_reference.h, probe_functions), under the probe's uniforms.
ref::dvec3 cpu_value(const FunctionProbe& probe, const std::vector<float>& in, bool ggx_without_pi = false) {
  const auto& functions = ref::probe_functions();
  auto it = functions.find(probe.function);
  if (it == functions.end()) {
    ADD_FAILURE() << "tools/grade/lab_functions.json probes " << probe.function << " (lab " << probe.lab
                  << "), which instructor/reference/cpu_reference.cpp's probe_functions() does not evaluate";
    return ref::dvec3(0.0);
  }
  ref::ShadingSettings settings;
  settings.stage = 3;
  for (const grade::ProbeUniform& u : probe.uniforms) {
    if (u.name == "u_attenuation_model") settings.attenuation_model = static_cast<int>(u.value);
    if (u.name == "u_gamma") settings.gamma = u.value;
  }
  Arguments a{in};
  const ref::dvec3 value = it->second(a, settings);
  return ggx_without_pi && probe.function == "distribution_ggx" ? value * 3.14159265358979323846 : value;
}

// What a map of a lab 6 pass probe returns at (s, t) and level `level` (function_probes.h,
// ProbeMap): its value, its coordinates, or its value times 1 + the level.
ref::dvec3 probe_map_value(const grade::ProbeMap& map, ref::dvec2 st, double level) {
  const ref::dvec3 value(map.value);
  switch (map.fill) {
    case grade::ProbeMap::Fill::Coordinates: return {st.x, st.y, value.z};
    case grade::ProbeMap::Fill::Levels: return value * (1.0 + level);
    default: return value;
  }
}

// GL's (s, t) of direction d in the equirectangular convention (ibl_reference.h: v from the
// top row; GL's t from the bottom).
ref::dvec2 equirect_st(ref::dvec3 d) {
  const ref::dvec2 uv = ref::equirect_uv(d);
  return {uv.x, 1.0 - uv.y};
}

// A lab 6 probe of ibl.frag from ibl_reference.h's split sum, its three factors read from the
// probe's maps where the split sum looks them up: the BRDF table's texel i holds the grid
// value i / (KIT_BRDF_LUT_SIZE - 1) (handouts/06-ibl.md), the prefiltered map's level is the
// roughness times KIT_PREFILTER_LEVELS - 1.
std::vector<ref::dvec3> cpu_ibl_values(const FunctionProbe& probe) {
  ref::dvec3 camera(0.0);
  for (const grade::ProbeUniform& u : probe.uniforms)
    if (u.name == "u_camera_position") camera = ref::dvec3(u.vec3);
  const grade::ProbeMap* irradiance = nullptr;
  const grade::ProbeMap* prefiltered = nullptr;
  const grade::ProbeMap* table = nullptr;
  for (const grade::ProbeMap& m : probe.maps)
    (m.sampler == "u_irradiance" ? irradiance : m.sampler == "u_prefiltered" ? prefiltered : table) = &m;
  std::vector<ref::dvec3> values;
  for (const grade::ProbeCase& c : probe.cases) {
    const ref::SurfaceSample s = texel_sample(c.inputs);
    const ref::SplitSumLookups at = ref::split_sum_lookups(s, camera);
    const auto table_coordinate = [](double grid) { return (grid * (KIT_BRDF_LUT_SIZE - 1) + 0.5) / KIT_BRDF_LUT_SIZE; };
    const ref::dvec3 abc = probe_map_value(*table, {table_coordinate(at.n_dot_v), table_coordinate(s.roughness)}, 0.0);
    const ref::dvec3 p = probe_map_value(*prefiltered, equirect_st(at.r), s.roughness * (KIT_PREFILTER_LEVELS - 1));
    const ref::dvec3 e = probe_map_value(*irradiance, equirect_st(at.n), 0.0);
    values.push_back(ref::split_sum_combination(s, abc, p, e));
  }
  return values;
}

// The texel a geometry probe's texture `unit` gives at vertex `v`: nearest, repeating, row
// 0 at v = 0 (glTF's UVs read the image as loaded), each channel / 255 (colour textures'
// RGB decoded from sRGB).
ref::dvec4 probe_texel(const grade::GeometryProbeSetup& setup, int unit, const Vertex& v) {
  const MaterialTexture& t = setup.material.texture(unit);
  if (t.image < 0) return ref::dvec4(0.5, 0.5, 1.0, 1.0);  // the framework's flat normal
  const ImageRgba8& image = setup.images.at(static_cast<size_t>(t.image));
  const glm::dvec2 uv(t.uv.of(v));
  const auto wrap = [](double x, int size) {
    const int i = static_cast<int>(std::floor((x - std::floor(x)) * size));
    return std::min(i, size - 1);
  };
  const unsigned char* texel =
      &image.pixels[(static_cast<size_t>(wrap(uv.y, image.height)) * image.width + wrap(uv.x, image.width)) * 4];
  ref::dvec4 out;
  for (int c = 0; c < 4; ++c) {
    const double value = texel[c] / 255.0;
    out[c] = c < 3 && material_texture_is_color(unit) ? srgb_to_linear(value) : value;
  }
  return out;
}

// A lab 1 or 4 geometry probe from the CPU reference (cpu_reference.h: base_color,
// normal_matrix, world_tangent_frame, mapped_normal) and glTF's material definitions.
std::vector<ref::dvec3> cpu_geometry_values(const FunctionProbe& probe) {
  const grade::GeometryProbeSetup& setup = *probe.geometry;
  const Material& m = setup.material;
  const ref::dmat4 model(setup.model), view(setup.view);
  std::vector<ref::dvec3> values;
  const int n = static_cast<int>(probe.cases.size());
  for (int i = 0; i < n; ++i) {
    const Vertex v = grade::geometry_probe_vertex(probe.cases[static_cast<size_t>(i)].inputs);
    const ref::dvec4 base = ref::base_color(m, probe_texel(setup, KIT_UNIT_BASE_COLOR, v), ref::vertex_color(v));
    const ref::dvec4 mr = probe_texel(setup, KIT_UNIT_METALLIC_ROUGHNESS, v);
    const bool discarded = m.alpha_mode == KIT_ALPHA_MASK && base.a < m.alpha_cutoff;
    ref::dvec3 value(0.0);
    switch (setup.attachment) {
      case KIT_GBUF_POSITION:
        value = ref::dvec3(glm::inverse(view) * ref::dvec4(ref::dvec3(grade::geometry_probe_view_point(i, n)), 1.0));
        break;
      case KIT_GBUF_NORMAL: {
        const bool mapped = probe.lab == 4 && m.texture(KIT_UNIT_NORMAL_MAP).image >= 0;
        value = mapped ? ref::mapped_normal(ref::world_tangent_frame(model, ref::dvec3(v.normal), ref::dvec4(v.tangent)),
                                            ref::dvec3(probe_texel(setup, KIT_UNIT_NORMAL_MAP, v)), m.normal_scale)
                       : glm::normalize(ref::normal_matrix(model) * ref::dvec3(v.normal));
        if (setup.back_faces) value = -value;  // glTF: a double-sided material's back faces the other way
        break;
      }
      case KIT_GBUF_ALBEDO: value = setup.alpha ? ref::dvec3(discarded ? 0.0 : base.a, 0.0, 0.0) : ref::dvec3(base); break;
      case KIT_GBUF_MATERIAL: value = ref::dvec3(m.metallic_factor * mr.b, m.roughness_factor * mr.g, 0.0); break;
      default: value = ref::dvec3(m.emissive) * ref::dvec3(probe_texel(setup, KIT_UNIT_EMISSIVE, v));
    }
    values.push_back(value);
  }
  return values;
}

// A lab 7 probe of light_volume.frag from the CPU reference (cpu_reference.h,
// light_volume_term): the light the probe draws (u_probe_light) as the framework uploads it,
// with its volume radius, the camera and model its uniforms say.
std::vector<ref::dvec3> cpu_light_volume_values(const FunctionProbe& probe) {
  ref::ShadingSettings settings;
  settings.stage = 7;
  ref::dvec3 camera(0.0);
  size_t light = 0;
  for (const grade::ProbeUniform& u : probe.uniforms) {
    if (u.name == "u_camera_position") camera = ref::dvec3(u.vec3);
    if (u.name == "u_attenuation_model") settings.attenuation_model = static_cast<int>(u.value);
    if (u.name == "u_probe_light") light = static_cast<size_t>(u.value);
  }
  const grade::LightVolumeProbeSetup& setup = *probe.light_volume;
  std::vector<ref::dvec3> values;
  for (const grade::ProbeCase& c : probe.cases) {
    const ref::SurfaceSample s = texel_sample(c.inputs);
    values.push_back(ref::light_volume_term(s, camera, ref::uploaded_light(setup.lights.at(light)),
                                            setup.volume_radii.at(light), settings));
  }
  return values;
}

// A lab 5 pass probe's values from the CPU reference (cpu_reference.h, lab 5), every case at
// once: the blur's value at a texel depends on its neighbours'.
std::vector<ref::dvec3> cpu_pass_values(const FunctionProbe& probe) {
  if (probe.file == "ibl.frag") return cpu_ibl_values(probe);
  if (probe.light_volume) return cpu_light_volume_values(probe);
  if (probe.geometry) return cpu_geometry_values(probe);
  ref::ShadingSettings settings;
  settings.stage = 5;
  bool horizontal = true;
  for (const grade::ProbeUniform& u : probe.uniforms) {
    if (u.name == "u_bloom_threshold") settings.bloom_threshold = u.value;
    if (u.name == "u_gamma") settings.gamma = u.value;
    if (u.name == "u_postprocess_enabled") settings.postprocess = u.value != 0.0f;
    if (u.name == "u_horizontal") horizontal = u.value != 0.0f;
  }
  const int n = static_cast<int>(probe.cases.size());
  const int width = probe.column ? 1 : n, height = probe.column ? n : 1;
  std::vector<Image> inputs(probe.arguments.size(), Image(width, height, 4));
  for (int i = 0; i < n; ++i)
    for (size_t a = 0; a < inputs.size(); ++a)
      for (int k = 0; k < 3; ++k)
        inputs[a].at(probe.column ? 0 : i, probe.column ? i : 0, k) = probe.cases[static_cast<size_t>(i)].inputs[a * 3 + k];
  Image out;
  if (probe.file == "bright.frag") {
    out = inputs[0];
    for (int i = 0; i < n; ++i) {
      const int x = probe.column ? 0 : i, y = probe.column ? i : 0;
      const ref::dvec3 kept = ref::bright_pass(ref::pixel_rgb(inputs[0], x, y), settings.bloom_threshold);
      for (int k = 0; k < 3; ++k) out.at(x, y, k) = static_cast<float>(kept[k]);
    }
  } else if (probe.file == "blur.frag")
    out = ref::blur_pass(inputs[0], horizontal);
  else
    out = ref::composite(inputs[0], inputs[1], settings);
  std::vector<ref::dvec3> values;
  for (int i = 0; i < n; ++i) values.push_back(ref::pixel_rgb(out, probe.column ? 0 : i, probe.column ? i : 0));
  return values;
}

// How many compared values of every probe are off the CPU reference (finite_only cases:
// how many are not finite), and the first such, in words.
int cpu_disagreements(const nlohmann::json& reference, std::string* first, bool ggx_without_pi = false,
                      std::string* worst = nullptr) {
  int off = 0;
  double worst_relative = 0.0;
  for (const FunctionProbe& table : grade::all_function_probes()) {
    const std::vector<FunctionProbe> run = grade::probes_to_run(table.lab, reference);
    const FunctionProbe& probe = *std::find_if(run.begin(), run.end(), [&](const FunctionProbe& p) { return p.id == table.id; });
    const std::vector<glm::vec4> expected = grade::expected_probe_values(reference, probe);
    EXPECT_EQ(expected.size(), probe.cases.size()) << probe.id << ": probes.json lacks it (./kit rebaseline)";
    const std::vector<ref::dvec3> pass_values = probe.pass ? cpu_pass_values(probe) : std::vector<ref::dvec3>{};
    for (size_t i = 0; i < expected.size(); ++i) {
      const ref::dvec3 cpu = probe.pass ? pass_values.at(i) : cpu_value(probe, probe.cases[i].inputs, ggx_without_pi);
      const int components = probe.result == ProbeType::Float ? 1 : 3;
      for (int k = 0; k < components; ++k) {
        const double gpu = expected[i][k];
        if (!probe.cases[i].finite_only && !probe.srgb_decoded && std::abs(cpu[k]) > 1e-3) {
          const double relative = std::abs(gpu - cpu[k]) / std::abs(cpu[k]);
          if (worst && relative > worst_relative) {
            worst_relative = relative;
            std::ostringstream s;
            s << relative << " (" << probe.id << " case " << i << ")";
            *worst = s.str();
          }
        }
        const bool bad = probe.cases[i].finite_only
                             ? !std::isfinite(gpu)
                             : probe.srgb_decoded ? !(std::abs(gpu - cpu[k]) <= kCpuSrgbTolerance * std::abs(cpu[k]) + 2e-3)
                                                  : !(std::abs(gpu - cpu[k]) <= kCpuRelativeTolerance * std::abs(cpu[k]) + 1e-7);
        if (bad && off++ == 0 && first) {
          std::ostringstream s;
          s << probe.id << " case " << i << " component " << k << ": probes.json " << gpu << ", CPU " << cpu[k];
          *first = s.str();
        }
      }
    }
  }
  return off;
}

TEST(FunctionProbes, ExpectedValuesMatchTheCpuReference) {
  const nlohmann::json reference = probes_reference();
  ASSERT_FALSE(reference.is_null()) << "no tools/grade/references/probes.json (kit-grade --update-references)";
  const std::vector<std::string> stale = grade::probes_reference_differences(reference);
  EXPECT_TRUE(stale.empty()) << stale.front();
  std::string first, worst;
  EXPECT_EQ(cpu_disagreements(reference, &first, false, &worst), 0) << first;
  std::printf("largest relative difference from the CPU reference: %s\n", worst.c_str());
  // Witness: the comparison sees a GGX that lacks its pi.
  EXPECT_GT(cpu_disagreements(reference, nullptr, true), 20);
}

// A solution's lab folder with `find` replaced by `replace` in `file`, as a lab root.
std::filesystem::path lab_with(const std::string& name, const std::string& folder, const std::string& file,
                               const std::string& find, const std::string& replace) {
  const std::filesystem::path root = temp_dir("function_probes_" + name);
  const std::filesystem::path lab = root / folder;
  std::filesystem::create_directories(lab);
  for (const auto& entry : std::filesystem::directory_iterator(kit_root() / "solutions" / folder))
    std::filesystem::copy_file(entry.path(), lab / entry.path().filename());
  std::ifstream in(lab / file);
  std::string text((std::istreambuf_iterator<char>(in)), {});
  size_t at = text.find(find);
  EXPECT_NE(at, std::string::npos) << file << " no longer holds " << find;
  while (at != std::string::npos) {
    text.replace(at, find.size(), replace);
    at = text.find(find, at + replace.size());
  }
  std::ofstream(lab / file) << text;
  return root;
}

// Lab 2's solution with `find` replaced by `replace` in brdf.glsl, as a lab folder.
std::filesystem::path lab2_with(const std::string& name, const std::string& find, const std::string& replace) {
  return lab_with(name, "02-lighting", "brdf.glsl", find, replace);
}

std::map<std::string, grade::ProbeOutcome> probe_lab(int lab, const std::filesystem::path& root) {
  context();
  const nlohmann::json reference = probes_reference();
  const auto values = grade::run_function_probes(find_stage(lab), root, reference);
  std::map<std::string, grade::ProbeOutcome> out;
  for (const FunctionProbe& probe : grade::probes_to_run(lab, reference)) {
    auto it = values.find(probe.id);
    out[probe.id] = grade::compare_probe(probe, it == values.end() ? grade::ProbeValues{} : it->second,
                                         grade::expected_probe_values(reference, probe));
  }
  return out;
}

// The ids of the probes that differ, in order.
std::vector<std::string> differing(const std::map<std::string, grade::ProbeOutcome>& probes) {
  std::vector<std::string> out;
  for (const auto& [id, outcome] : probes)
    if (outcome.status == grade::kProbeDiffers) out.push_back(id);
  return out;
}

TEST(FunctionProbes, TheSolutionAgreesEverywhere) {
  for (const auto& [id, outcome] : probe_lab(2, kit_root() / "solutions")) EXPECT_EQ(outcome.status, grade::kProbeAgrees) << outcome.message;
}

TEST(FunctionProbes, AGgxWithoutPiIsNamedWithItsFactor) {
  auto probes = probe_lab(2, lab2_with("ggx_no_pi", "KIT_PI * d * d", "d * d"));
  const grade::ProbeOutcome& ggx = probes.at("distribution_ggx");
  EXPECT_EQ(ggx.status, grade::kProbeDiffers);
  EXPECT_NE(ggx.message.find("distribution_ggx(n_dot_h = "), std::string::npos) << ggx.message;
  EXPECT_NE(ggx.shape.find("(pi)"), std::string::npos) << ggx.message;
  // Every other function agrees, but cook_torrance (and its term probe), which calls it.
  for (const auto& [id, outcome] : probes)
    if (id != "distribution_ggx" && id != "cook_torrance" && id != "cook_torrance/terms") {
      EXPECT_EQ(outcome.status, grade::kProbeAgrees) << outcome.message;
    }
}

TEST(FunctionProbes, SwappedArgumentsAreNamed) {
  auto probes = probe_lab(2, lab2_with("ggx_swapped", "float distribution_ggx(float n_dot_h, float alpha)",
                                     "float distribution_ggx(float alpha, float n_dot_h)"));
  const grade::ProbeOutcome& ggx = probes.at("distribution_ggx");
  EXPECT_EQ(ggx.status, grade::kProbeDiffers);
  EXPECT_EQ(ggx.shape, "n_dot_h and alpha swapped") << ggx.message;
}

TEST(FunctionProbes, ARenamedFunctionLosesOnlyItsOwnProbe) {
  auto probes = probe_lab(2, lab2_with("ggx_renamed", "distribution_ggx(", "my_ggx("));
  EXPECT_EQ(probes.at("distribution_ggx").status, grade::kProbeNotRun) << probes.at("distribution_ggx").message;
  for (const auto& [id, outcome] : probes)
    if (id != "distribution_ggx") {
      EXPECT_EQ(outcome.status, grade::kProbeAgrees) << outcome.message;
    }
}

// A contract (tools/grade/lab_functions.json) that cannot be read says where and why.
TEST(FunctionProbes, ABadContractNamesTheElementAndWhy) {
  const auto error_of = [](const char* text) {
    try {
      grade::contract_function_probes(nlohmann::json::parse(text), 2, "lab_functions.json");
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  const std::string type = error_of(R"({"labs": {"2": {"shader": "probe_brdf.frag", "functions": [
      {"function": "f", "file": "brdf.glsl", "arguments": [["x", "double"]], "result": "float", "cases": []}]}}})");
  EXPECT_NE(type.find("lab_functions.json: labs.2.functions[0].arguments[0]: a type is float, vec3 or Light"), std::string::npos)
      << type;
  const std::string missing = error_of(R"({"labs": {"2": {"shader": "probe_brdf.frag", "functions": [
      {"function": "f", "file": "brdf.glsl", "arguments": [["x", "float"], ["y", "float"]], "result": "float",
       "cases": [{"for": [["x", [1, 2]]]}]}]}}})");
  EXPECT_NE(missing.find("labs.2.functions[0].cases[0]: no value for the argument y"), std::string::npos) << missing;
  const std::string set = error_of(R"({"labs": {"2": {"shader": "probe_brdf.frag", "functions": [
      {"function": "f", "file": "brdf.glsl", "arguments": [["x", "float"]], "result": "float",
       "cases": [{"for": [["x", "$nowhere"]]}]}]}}})");
  EXPECT_NE(set.find("'$nowhere' names no value of \"sets\""), std::string::npos) << set;
  const std::string given = error_of(R"({"labs": {"2": {"shader": "probe_brdf.frag", "functions": [
      {"function": "f", "file": "brdf.glsl", "arguments": [["x", "float"]], "result": "float",
       "cases": [{"fixed": {"x": 1}}], "terms": {"id": "f/terms", "given": ["g"], "cases": []}}]}}})");
  EXPECT_NE(given.find("labs.2.functions[0].terms.given: an object: each function it calls"), std::string::npos) << given;
  // The kit's own: lab 2's functions, each its place in the probe shader (a term probe its function's).
  const std::vector<FunctionProbe> lab2 = grade::contract_function_probes(2);
  ASSERT_FALSE(lab2.empty());
  for (size_t i = 0, place = 0; i < lab2.size(); ++i)
    EXPECT_EQ(lab2[i].index, static_cast<int>(lab2[i].terms_only ? place - 1 : place++)) << lab2[i].id;
}

// probe_lab's probes as a grading run reads them (probe_outcomes): the term probes decided.
std::map<std::string, grade::ProbeOutcome> probe_terms(int lab, const std::filesystem::path& root) {
  context();
  const nlohmann::json reference = probes_reference();
  nlohmann::json child = {{"probes", nlohmann::json::object()}};
  for (const auto& [id, values] : grade::run_function_probes(find_stage(lab), root, reference))
    child["probes"][id] = grade::probe_values_json(values);
  std::map<std::string, grade::ProbeOutcome> out;
  for (grade::ProbeOutcome& o : grade::probe_outcomes(lab, child, reference)) out[o.probe->id] = o;
  return out;
}

// cook_torrance's term probe (term_probes.h): where fresnel_schlick, distribution_ggx and
// microfacet_geometry agree, the term that differs is named with the values that show it;
// the solution and a rewrite agree; a GGX without its pi (a called function that differs)
// leaves the terms untold (witness: the term probe alone would blame the specular term).
TEST(FunctionProbes, TermProbesNameTheTermOfCookTorrance) {
  for (const auto& [id, outcome] : probe_terms(2, kit_root() / "solutions")) EXPECT_EQ(outcome.status, grade::kProbeAgrees) << id;
  const auto rewritten = probe_terms(2, lab2_with("ct_regrouped", "vec3 specular = F * D * G / max(4.0 * n_dot_l * n_dot_v,",
                                                  "vec3 specular = (D * G) * F / max(4.0 * n_dot_v * n_dot_l,"));
  for (const auto& [id, outcome] : rewritten) EXPECT_EQ(outcome.status, grade::kProbeAgrees) << id << ": " << outcome.message;
  const struct {
    const char* name;
    const char* find;
    const char* replace;
    const char* part;
    const char* says;
  } mistakes[] = {
      {"ct_no_f", "vec3 specular = F * D * G / max(", "vec3 specular = vec3(D * G) / max(", "cook_torrance, fresnel",
       "without F: at l = v, where v.h = 1 and F = F0, it is 1/F0 times the expected, 25 for a dielectric"},
      {"ct_f0_albedo", "vec3 f0 = mix(vec3(0.04), albedo, metallic);", "vec3 f0 = albedo;", "cook_torrance, fresnel",
       "a black dielectric (albedo 0, metallic 0) reflects nothing"},
      {"ct_denominator_2", "max(4.0 * n_dot_l * n_dot_v,", "max(2.0 * n_dot_l * n_dot_v,", "cook_torrance, specular-denominator",
       "the specular term is 2 times the expected at every input"},
      {"ct_no_one_minus_f", "vec3 diffuse = (1.0 - F) * (1.0 - metallic)", "vec3 diffuse = (1.0 - metallic)",
       "cook_torrance, diffuse", "1/(1 - F0) = 1.042 times the expected"},
      {"ct_metal_diffuse", "vec3 diffuse = (1.0 - F) * (1.0 - metallic)", "vec3 diffuse = (1.0 - F)", "cook_torrance, diffuse",
       "a metal (metallic 1) gets a diffuse lobe"},
      {"ct_clamped", "return diffuse + specular;", "return diffuse + min(specular, vec3(1.0));", "cook_torrance, specular-clamp",
       "the specular term is capped at 1"},
  };
  for (const auto& m : mistakes) {
    const grade::ProbeOutcome terms = probe_terms(2, lab2_with(m.name, m.find, m.replace)).at("cook_torrance/terms");
    EXPECT_EQ(terms.status, grade::kProbeDiffers) << m.name;
    EXPECT_EQ(terms.part, m.part) << m.name << ": " << terms.message;
    EXPECT_NE(terms.message.find(m.says), std::string::npos) << m.name << ": " << terms.message;
  }
  const grade::ProbeOutcome ggx = probe_terms(2, lab2_with("ct_ggx_no_pi", "KIT_PI * d * d", "d * d")).at("cook_torrance/terms");
  EXPECT_EQ(ggx.status, grade::kProbeExplained) << ggx.message;
  EXPECT_EQ(ggx.part, "cook_torrance, distribution");  // the term distribution_ggx is
}

// light_radiance read term by term where spot_cone_factor agrees: the falloff's power named;
// cones swapped inside spot_cone_factor leave light_radiance's own message untold.
TEST(FunctionProbes, LightRadianceIsReadTermByTerm) {
  const auto linear = probe_terms(3, lab_with("radiance_linear", "03-attenuation", "attenuation.glsl",
                                              "intensity = light.flux / (4.0 * KIT_PI * r2);",
                                              "intensity = light.flux / (4.0 * KIT_PI * sqrt(r2));"));
  const grade::ProbeOutcome& physical = linear.at("light_radiance/physical");
  EXPECT_EQ(physical.part, "light_radiance, intensity") << physical.message;
  EXPECT_NE(physical.message.find("it falls off as 1/r, not 1/r^2"), std::string::npos) << physical.message;
  EXPECT_NE(physical.message.find("light_radiance(light = "), std::string::npos) << physical.message;  // its first input stays
  const auto swapped = probe_terms(3, lab_with("cones_swapped", "03-attenuation", "attenuation.glsl",
                                               "(cos_angle - light.cos_outer) / max(light.cos_inner - light.cos_outer,",
                                               "(cos_angle - light.cos_inner) / max(light.cos_outer - light.cos_inner,"));
  EXPECT_EQ(swapped.at("spot_cone_factor").status, grade::kProbeDiffers);
  EXPECT_EQ(swapped.at("light_radiance/physical").status, grade::kProbeDiffers);
  EXPECT_EQ(swapped.at("light_radiance/physical").part, "light_radiance, spot-cone");  // the term spot_cone_factor is
  EXPECT_EQ(swapped.at("light_radiance/physical").message.find("term by term"), std::string::npos);
}

TEST(FunctionProbes, AMissingGuardIsReportedAsNotFinite) {
  auto probes = probe_lab(2, lab2_with("ggx_unguarded", "max(KIT_PI * d * d, KIT_MIN_GGX_DENOMINATOR)", "(KIT_PI * d * d)"));
  const grade::ProbeOutcome& ggx = probes.at("distribution_ggx");
  EXPECT_EQ(ggx.status, grade::kProbeDiffers);
  EXPECT_NE(ggx.message.find("expected a finite value"), std::string::npos) << ggx.message;
}

}  // namespace
}  // namespace kit::test

namespace kit::test {
namespace {

// Lab 5's passes, each drawn alone (FunctionProbe::pass): the solution's agree at every texel,
// and a bright pass that ignores its threshold is named with a texel, while blur.frag and
// composite.frag, drawn on their own inputs, still agree (witness: the pass, not its callers).
TEST(FunctionProbes, APassDrawnAloneIsNamedWithItsTexel) {
  for (const auto& [id, outcome] : probe_lab(5, kit_root() / "solutions"))
    EXPECT_EQ(outcome.status, grade::kProbeAgrees) << outcome.message;
  auto probes = probe_lab(5, lab_with("bright_threshold_ignored", "05-postprocess", "bright.frag",
                                      "luminance > u_bloom_threshold ? c : vec3(0.0)", "c"));
  const grade::ProbeOutcome& bright = probes.at("bright/threshold-1");
  EXPECT_EQ(bright.status, grade::kProbeDiffers);
  // Under the threshold 1: the texels of luminance 0.25, 0.75, 0.45, 0.28 and 0.8 (0 stays 0).
  EXPECT_NE(bright.message.find("bright.frag at texel 1 (u_hdr = (0.25, 0.25, 0.25)) writes (0.25, 0.25, 0.25), "
                                "expected (0, 0, 0); 5 of 9 texels differ"),
            std::string::npos) << bright.message;
  for (const char* other : {"blur/horizontal", "blur/vertical", "composite/bloom-on", "composite/gamma-1.0", "composite/bloom-off"})
    EXPECT_EQ(probes.at(other).status, grade::kProbeAgrees) << probes.at(other).message;
  const std::vector<std::string> feedback = grade::probe_feedback(
      {probes.at("bright/threshold-1"), probes.at("blur/vertical")}, true);
  ASSERT_EQ(feedback.size(), 1u);
  EXPECT_EQ(feedback[0].rfind("Your pass bright.frag at texel", 0), 0u) << feedback[0];
}

}  // namespace
}  // namespace kit::test

namespace kit::test {
namespace {

// Lab 6's ibl.frag, drawn four times with its maps filled to show one part each
// (function_probes.cpp, make_lab6): the solution agrees everywhere; the irradiance looked up
// at the reflection vector differs only where the maps hold their directions, while a diffuse
// term without its 1/pi differs wherever the diffuse term shows, and not where only the
// specular term does (witness: the probes tell the two apart, where the images could not).
TEST(FunctionProbes, IblProbesTellItsPartsApart) {
  for (const auto& [id, outcome] : probe_lab(6, kit_root() / "solutions"))
    EXPECT_EQ(outcome.status, grade::kProbeAgrees) << outcome.message;
  auto at_r = probe_lab(6, lab_with("irradiance_at_r", "06-ibl", "ibl.frag", "kit_irradiance(n)", "kit_irradiance(reflect(-v, n))"));
  EXPECT_EQ(differing(at_r), std::vector<std::string>{"ibl/directions"});
  EXPECT_NE(at_r.at("ibl/directions").message.find("ibl.frag at texel 0 (u_gbuffer_position = (0.5, 0.25, 3)"), std::string::npos)
      << at_r.at("ibl/directions").message;
  auto no_pi = probe_lab(6, lab_with("diffuse_no_pi", "06-ibl", "ibl.frag", "kit_irradiance(n) / KIT_PI", "kit_irradiance(n)"));
  EXPECT_EQ(differing(no_pi), (std::vector<std::string>{"ibl/diffuse", "ibl/directions", "ibl/table"}));
  EXPECT_NE(no_pi.at("ibl/diffuse").shape.find("(pi)"), std::string::npos) << no_pi.at("ibl/diffuse").message;
  EXPECT_EQ(no_pi.at("ibl/diffuse").probe->part(), "ibl.frag, diffuse");
}

}  // namespace
}  // namespace kit::test

namespace kit::test {
namespace {

// Labs 1 and 4's geometry pass, one attachment at a time (function_probes.cpp, make_geometry):
// the solutions agree everywhere; metallic and roughness swapped in out_material differ in
// the two probes that read it, and the metallic-roughness texture read at the base colour's
// UV differs only where textures vary by texel (witness: the plain probe's one texel hides a
// UV, so the two are told apart), each named with the case's vertex attributes.
TEST(FunctionProbes, GeometryProbesTellAttachmentsAndUvsApart) {
  for (int lab : {1, 4})
    for (const auto& [id, outcome] : probe_lab(lab, kit_root() / "solutions"))
      EXPECT_EQ(outcome.status, grade::kProbeAgrees) << outcome.message;
  auto swapped = probe_lab(1, lab_with("material_swapped", "01-gbuffer", "gbuffer.frag", "vec4(metallic, roughness, 0.0, 1.0)",
                                       "vec4(roughness, metallic, 0.0, 1.0)"));
  EXPECT_EQ(differing(swapped), (std::vector<std::string>{"gbuffer/metallic-roughness", "gbuffer/uv-material"}));
  // As docs/grading.md and handouts/01-gbuffer.md quote it.
  EXPECT_NE(swapped.at("gbuffer/metallic-roughness").message.find(
                "gbuffer.frag at texel 0 (a_normal = (0.2, 0.3, 1.2), a_tangent = (1, 0, 0.1, 1), a_texcoord0 = (0.125, "
                "0.375), a_texcoord1 = (0.375, 0.125), a_color = (1, 0.8, 0.6, 1)) writes (0.3529, 0.549, 0), expected "
                "(0.549, 0.3529, 0); 6 of 6 texels differ (out_material.rgb; u_metallic_factor 0.7, u_roughness_factor "
                "0.9, a metallic-roughness texture uniformly (60, 100, 200))"),
            std::string::npos)
      << swapped.at("gbuffer/metallic-roughness").message;
  EXPECT_EQ(swapped.at("gbuffer/metallic-roughness").probe->part(), "gbuffer.frag, metallic-roughness");
  auto at_base_uv = probe_lab(1, lab_with("mr_at_base_uv", "01-gbuffer", "gbuffer.frag", "kit_metallic_roughness_uv(v_texcoords)",
                                          "kit_base_color_uv(v_texcoords)"));
  EXPECT_EQ(differing(at_base_uv), std::vector<std::string>{"gbuffer/uv-material"});
}

}  // namespace
}  // namespace kit::test

namespace kit::test {
namespace {

// Lab 7's light_volume.frag, drawn alone as one light's volume over rows of G-buffer texels
// (pass_probes.cpp, make_lab7), each probe set up so that one part of the term shows: the
// solution agrees everywhere, and so do the catalogue's equivalents (no sphere test, texture()
// at gl_FragCoord / u_resolution); the cosine dropped differs only in the cosine's probe, the
// first light read for every volume only in the light's, and the view vector taken from the
// origin only in the view vector's (witness: with the camera at the origin elsewhere, the
// other probes cannot see it), each named at its texel as a pass is.
TEST(FunctionProbes, LightVolumeProbesTellItsPartsApart) {
  for (const auto& [id, outcome] : probe_lab(7, kit_root() / "solutions"))
    EXPECT_EQ(outcome.status, grade::kProbeAgrees) << outcome.message;
  const char* folder = "07-lightvolumes";
  const char* file = "light_volume.frag";
  const char* test = "    if (dot(to_light, to_light) > light.volume_radius * light.volume_radius) return;\n";
  for (const auto& [id, outcome] : probe_lab(7, lab_with("no_sphere_test", folder, file, test, "")))
    EXPECT_EQ(outcome.status, grade::kProbeAgrees) << outcome.message;
  auto no_cosine = probe_lab(7, lab_with("no_cosine", folder, file, "light_radiance(light, p) * n_dot_l;", "light_radiance(light, p);"));
  EXPECT_EQ(differing(no_cosine), std::vector<std::string>{"light_volume/cosine"});
  EXPECT_EQ(no_cosine.at("light_volume/cosine").probe->part(), "light_volume.frag, cosine");
  EXPECT_EQ(grade::probe_feedback({no_cosine.at("light_volume/cosine")}, true).at(0).rfind(
                "Your pass light_volume.frag at texel 1 (u_gbuffer_position = (0.25, 0.5, -4)", 0),
            0u)
      << no_cosine.at("light_volume/cosine").message;
  auto first_light = probe_lab(7, lab_with("first_light", folder, file, "kit_light(v_light)", "kit_light(0)"));
  EXPECT_EQ(differing(first_light), std::vector<std::string>{"light_volume/light"});
  auto from_origin = probe_lab(7, lab_with("view_from_origin", folder, file, "normalize(u_camera_position - p)", "normalize(-p)"));
  EXPECT_EQ(differing(from_origin), std::vector<std::string>{"light_volume/view"});
}

// A lab 7 probe's difference placed by its shape (term_probes.h, light_volume_terms): n.l
// taken with the unnormalised vector to the light makes each lit texel d times the expected
// (d its distance from the light), which only the probes with surfaces off 1 m show, the
// falloff's and the sphere test's: all are placed in the cosine, with the cosine dropped
// (the same family). The falloff taken at the camera makes every texel of a probe whose
// surfaces are all 1 m from the light one factor off: placed in the falloff, with no falloff
// at all. Witness: the falloff dropped is not placed in the cosine (its ratio grows as d^2,
// cut by the range window), so its probes keep their own parts.
TEST(FunctionProbes, LightVolumeDifferencesArePlacedByTheirShape) {
  const char* folder = "07-lightvolumes";
  const char* file = "light_volume.frag";
  const auto parts = [](const std::map<std::string, grade::ProbeOutcome>& outcomes) {
    std::set<std::string> out;
    for (const auto& [id, o] : outcomes)
      if (o.status == grade::kProbeDiffers) out.insert(o.part);
    return out;
  };
  auto unnormalised = probe_terms(7, lab_with("cosine_unnormalised", folder, file, "float n_dot_l = dot(n, l);",
                                            "float n_dot_l = dot(n, to_light);"));
  EXPECT_EQ(differing(unnormalised), (std::vector<std::string>{"light_volume/falloff-physical", "light_volume/falloff-simple",
                                                               "light_volume/falloff-spot", "light_volume/sphere-ranged",
                                                               "light_volume/sphere-unranged"}));
  EXPECT_EQ(parts(unnormalised), std::set<std::string>{"light_volume.frag, cosine"});
  EXPECT_NE(unnormalised.at("light_volume/falloff-physical").message.find("d times the expected"), std::string::npos)
      << unnormalised.at("light_volume/falloff-physical").message;
  auto at_camera = probe_terms(7, lab_with("falloff_at_camera", folder, file, "* light_radiance(light, p) *",
                                         "* light_radiance(light, u_camera_position) *"));
  for (const char* id : {"light_volume/view", "light_volume/cosine", "light_volume/light", "light_volume/lookup"})
    EXPECT_EQ(at_camera.at(id).part, "light_volume.frag, falloff") << id << ": " << at_camera.at(id).message;
  auto no_falloff = probe_terms(7, lab_with("no_falloff", folder, file, "* light_radiance(light, p) *",
                                          "* light.color * light.intensity *"));
  EXPECT_EQ(parts(no_falloff), (std::set<std::string>{"light_volume.frag, falloff", "light_volume.frag, sphere test",
                                                       "light_volume.frag, sphere test (a ranged light)"}));
}

}  // namespace
}  // namespace kit::test
