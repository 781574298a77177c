#include "frames/pass_probes.h"

#include <glm/gtc/matrix_transform.hpp>

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "gbuffer_layout.h"
#include "render/renderer.h"
#include "scene/scene.h"

namespace kit::grade {

namespace {

void push(std::vector<float>& to, float v) { to.push_back(v); }
void push(std::vector<float>& to, glm::vec3 v) { to.insert(to.end(), {v.x, v.y, v.z}); }

// A pass probe of lab `lab`'s `file` (labs 1, 4, 5, 6 and 7), drawn alone: its function is
// "main"; labs 2 and 3's function probes come from their contract (lab_functions.h).
FunctionProbe pass_probe(int lab, const std::string& file, std::vector<ProbeArgument> arguments, ProbeType result) {
  FunctionProbe p;
  p.id = file;
  p.lab = lab;
  p.file = file;
  p.function = "main";
  p.shader = file;
  p.arguments = std::move(arguments);
  p.result = result;
  p.pass = true;
  return p;
}

// Lab 5's passes, each drawn alone. Every input is exact in half float (the inputs are
// RGBA16F textures, as the passes' own are), and no luminance lies within 10 % of a threshold,
// where the catalogue's equivalents (a rounded luminance, step() for >) may differ.
FunctionProbe lab5_pass(const std::string& file, const std::string& id, const std::string& setting,
                        std::vector<ProbeArgument> arguments, std::vector<ProbeUniform> uniforms) {
  FunctionProbe p = pass_probe(5, file, std::move(arguments), ProbeType::Vec3);
  p.id = id;
  p.setting = setting;
  p.uniforms = std::move(uniforms);
  return p;
}

std::vector<FunctionProbe> make_lab5() {
  std::vector<FunctionProbe> probes;
  using T = ProbeType;
  for (float threshold : {1.0f, 0.5f}) {
    FunctionProbe p = lab5_pass("bright.frag", threshold == 1.0f ? "bright/threshold-1" : "bright/threshold-0.5",
                                threshold == 1.0f ? "u_bloom_threshold = 1" : "u_bloom_threshold = 0.5",
                                {{"u_hdr", T::Vec3}}, {{"u_bloom_threshold", false, threshold}});
    // Luminances (Rec. 709): 0, 0.25, 0.75, 0.45 (a mean of 1.17), 0.28 (a mean of 0.58),
    // 1.25, 3.1, 0.8 (its mean 0.33), 64.
    for (glm::vec3 hdr : {glm::vec3(0.0f), glm::vec3(0.25f), glm::vec3(0.75f), glm::vec3(0.25f, 0.25f, 3.0f),
                          glm::vec3(1.0f, 0.0625f, 0.5f), glm::vec3(1.25f), glm::vec3(2.0f, 3.5f, 3.0f),
                          glm::vec3(0.125f, 1.0625f, 0.0f), glm::vec3(64.0f)}) {
      ProbeCase c;
      push(c.inputs, hdr);
      p.cases.push_back(c);
    }
    probes.push_back(p);
  }
  // An impulse in the middle of 17 texels: the output is the kernel, along a row for the
  // horizontal pass and down a column for the vertical one.
  for (bool horizontal : {true, false}) {
    FunctionProbe p = lab5_pass("blur.frag", horizontal ? "blur/horizontal" : "blur/vertical",
                                horizontal ? "u_horizontal = true, along a row" : "u_horizontal = false, down a column",
                                {{"u_bloom", T::Vec3}}, {{"u_horizontal", true, horizontal ? 1.0f : 0.0f}});
    p.column = !horizontal;
    for (int i = 0; i < 17; ++i) {
      ProbeCase c;
      push(c.inputs, i == 8 ? glm::vec3(1.0f, 0.5f, 0.25f) : glm::vec3(0.0f));
      p.cases.push_back(c);
    }
    probes.push_back(p);
  }
  struct Composite {
    const char* id;
    const char* setting;
    float gamma;
    bool postprocess;
  };
  for (Composite k : {Composite{"composite/bloom-on", "u_gamma = 2.2, u_postprocess_enabled = true", 2.2f, true},
                      Composite{"composite/gamma-1.0", "u_gamma = 1.0, u_postprocess_enabled = true", 1.0f, true},
                      Composite{"composite/bloom-off", "u_gamma = 2.2, u_postprocess_enabled = false", 2.2f, false}}) {
    FunctionProbe p = lab5_pass("composite.frag", k.id, k.setting, {{"u_hdr", T::Vec3}, {"u_bloom", T::Vec3}},
                                {{"u_gamma", false, k.gamma}, {"u_postprocess_enabled", true, k.postprocess ? 1.0f : 0.0f}});
    for (const auto& [hdr, bloom] : {std::pair{glm::vec3(0.0f), glm::vec3(0.0f)},
                                     std::pair{glm::vec3(0.25f, 0.5f, 1.0f), glm::vec3(0.0f)},
                                     std::pair{glm::vec3(0.5f, 0.25f, 0.125f), glm::vec3(0.25f)},
                                     std::pair{glm::vec3(1.0f), glm::vec3(0.5f, 1.0f, 2.0f)},
                                     std::pair{glm::vec3(4.0f, 2.0f, 1.0f), glm::vec3(1.0f, 0.5f, 0.25f)},
                                     std::pair{glm::vec3(0.0f), glm::vec3(2.0f)},
                                     std::pair{glm::vec3(16.0f, 8.0f, 4.0f), glm::vec3(0.125f, 0.0f, 8.0f)}}) {
      ProbeCase c;
      push(c.inputs, hdr);
      push(c.inputs, bloom);
      p.cases.push_back(c);
    }
    probes.push_back(p);
  }
  return probes;
}

// Lab 6's ibl.frag, drawn alone on eight G-buffer texels seen from a camera at the origin,
// five times: each time its maps are filled so that one part of the pass shows and the
// others cannot (function_probes.h, ProbeMap). What differs where tells the part apart:
//   diffuse     the prefiltered map black, the others uniform: the diffuse term's weights;
//   specular    the irradiance map black, the others uniform: the specular term's weights;
//   levels      the same, the prefiltered map's value growing with its level: also the
//               roughness it is looked up at;
//   directions  both maps their own coordinates: where each is looked up;
//   table       the BRDF table its own coordinates: at which (n.v, roughness) it is read.
// Every roughness is a whole prefiltered level (a multiple of 1 / (KIT_PREFILTER_LEVELS - 1)),
// so trilinear filtering and a GPU's faster blend of levels agree, and the normals and
// reflection vectors look up coordinates away from the maps' wrap and poles (u and t within
// [0.25, 0.75]), where bilinear filtering returns a texel's coordinates exactly.
std::vector<FunctionProbe> make_lab6() {
  using T = ProbeType;
  using F = ProbeMap::Fill;
  static_assert(KIT_PREFILTER_LEVELS == 6, "the roughnesses below are whole levels of 6");
  struct Texel {
    glm::vec3 position, normal, albedo;
    float metallic, roughness;
  };
  const Texel texels[] = {
      {{0.5f, 0.25f, 3.0f}, {0.25f, 0.125f, -1.0f}, {0.75f, 0.5f, 0.25f}, 0.0f, 0.2f},
      {{-1.0f, 0.5f, 2.0f}, {-0.5f, 0.25f, -1.0f}, {0.25f, 0.5f, 1.0f}, 0.5f, 0.4f},
      {{2.0f, -0.5f, 4.0f}, {0.0f, 0.0f, -1.0f}, {1.0f, 0.75f, 0.5f}, 1.0f, 0.6f},
      {{0.25f, -1.0f, 2.5f}, {0.5f, -0.25f, -1.0f}, {0.5f, 0.5f, 0.5f}, 0.0f, 0.8f},
      {{-2.0f, -0.25f, 3.5f}, {-0.25f, -0.5f, -1.0f}, {0.9f, 0.2f, 0.1f}, 0.5f, 1.0f},
      {{1.0f, 0.25f, 2.0f}, {0.125f, 0.375f, -1.0f}, {0.1f, 0.9f, 0.3f}, 0.0f, 0.4f},
      {{-0.5f, -0.5f, 1.5f}, {-0.375f, -0.125f, -1.0f}, {0.95f, 0.65f, 0.55f}, 1.0f, 0.6f},
      {{1.5f, 0.0f, 5.0f}, {0.375f, 0.25f, -1.0f}, {0.6f, 0.6f, 0.9f}, 0.5f, 0.2f},
  };
  const glm::vec3 black(0.0f), sky(0.75f, 0.5f, 0.25f), table(0.5f, 0.25f, 0.875f);
  struct Part {
    const char* term;
    const char* setting;
    ProbeMap irradiance, prefiltered, brdf_lut;
  };
  const Part parts[] = {
      {"diffuse", "camera at the origin; u_prefiltered black, u_irradiance (0.75, 0.5, 0.25) and u_brdf_lut (0.5, 0.25, 0.875) everywhere",
       {"u_irradiance", F::Uniform, sky}, {"u_prefiltered", F::Uniform, black}, {"u_brdf_lut", F::Uniform, table}},
      {"specular", "camera at the origin; u_irradiance black, u_prefiltered (0.75, 0.5, 0.25) and u_brdf_lut (0.5, 0.25, 0.875) everywhere",
       {"u_irradiance", F::Uniform, black}, {"u_prefiltered", F::Uniform, sky}, {"u_brdf_lut", F::Uniform, table}},
      {"levels", "camera at the origin; u_irradiance black, u_prefiltered (0.75, 0.5, 0.25) times 1 + its level, u_brdf_lut (0.5, 0.25, 0.875) everywhere",
       {"u_irradiance", F::Uniform, black}, {"u_prefiltered", F::Levels, sky}, {"u_brdf_lut", F::Uniform, table}},
      {"directions", "camera at the origin; u_irradiance and u_prefiltered hold their texture coordinates (s, t, 0.5), u_brdf_lut (0.5, 0.25, 0.875) everywhere",
       {"u_irradiance", F::Coordinates, glm::vec3(0.5f)}, {"u_prefiltered", F::Coordinates, glm::vec3(0.5f)}, {"u_brdf_lut", F::Uniform, table}},
      {"table", "camera at the origin; u_brdf_lut holds its texture coordinates (s, t, 0.875), u_irradiance and u_prefiltered (0.75, 0.5, 0.25) everywhere",
       {"u_irradiance", F::Uniform, sky}, {"u_prefiltered", F::Uniform, sky}, {"u_brdf_lut", F::Coordinates, table}},
  };
  std::vector<FunctionProbe> probes;
  for (const Part& part : parts) {
    FunctionProbe p = pass_probe(6, "ibl.frag",
                               {{"u_gbuffer_position", T::Vec3}, {"u_gbuffer_normal", T::Vec3},
                                {"u_gbuffer_albedo", T::Vec3}, {"u_gbuffer_material", T::Vec3}},
                               T::Vec3);
    p.id = std::string("ibl/") + part.term;
    p.term = part.term;
    p.setting = part.setting;
    p.maps = {part.irradiance, part.prefiltered, part.brdf_lut};
    ProbeUniform camera{"u_camera_position"};
    camera.is_vec3 = true;
    p.uniforms = {camera};
    for (const Texel& t : texels) {
      ProbeCase c;
      push(c.inputs, t.position);
      push(c.inputs, t.normal);
      push(c.inputs, t.albedo);
      push(c.inputs, glm::vec3(t.metallic, t.roughness, 0.0f));
      p.cases.push_back(c);
    }
    probes.push_back(p);
  }
  return probes;
}

// --- Lab 7: light_volume.frag, one light over a row of G-buffer texels ----------------------

// One G-buffer texel of a lab 7 probe: the surface `distance` from the light along
// `direction` (from the light, unit), its normal `tilt` turned from facing the light
// (cosine 1) towards `across` (unit, perpendicular to `direction`), and one of six materials.
struct VolumeTexel {
  glm::vec3 direction;
  float distance;
  float cosine = 1.0f;
  glm::vec3 across{0.0f};
  int material = 0;
};

ProbeCase volume_case(const glm::vec3& light, const VolumeTexel& t) {
  struct Surface {
    glm::vec3 albedo;
    float metallic, roughness;
  };
  // Roughness 0.35 and more: no GGX peak of a near-mirror, where float rounding would show.
  const Surface surfaces[] = {{{0.8f, 0.5f, 0.3f}, 0.0f, 0.5f}, {{0.3f, 0.6f, 0.9f}, 1.0f, 0.4f},
                              {{0.9f, 0.9f, 0.9f}, 0.5f, 0.7f}, {{0.2f, 0.8f, 0.4f}, 0.0f, 0.9f},
                              {{0.95f, 0.65f, 0.55f}, 1.0f, 0.6f}, {{0.5f, 0.3f, 0.7f}, 0.25f, 0.35f}};
  const Surface& m = surfaces[t.material % 6];
  const float sine = std::sqrt(std::max(0.0f, 1.0f - t.cosine * t.cosine));
  ProbeCase c;
  push(c.inputs, light + t.distance * t.direction);
  push(c.inputs, glm::normalize(-t.cosine * t.direction + sine * t.across));
  push(c.inputs, m.albedo);
  push(c.inputs, glm::vec3(m.metallic, m.roughness, 0.0f));
  return c;
}

// One probe of lab 7: the light drawn (always light 2 of three), the model, the camera, the texels.
struct VolumePart {
  const char* id;
  const char* term;
  const char* setting;
  std::vector<Light> lights;
  std::vector<float> radii;
  int model;
  glm::vec3 camera;
  std::vector<VolumeTexel> texels;
  bool column = false;
};

Light volume_light(int type, glm::vec3 position, glm::vec3 colour, float intensity, float range) {
  Light l;
  l.type = type;
  l.position = position;
  l.color = colour;
  l.intensity = intensity;
  l.range = range;
  l.direction = glm::vec3(0.0f, 0.0f, -1.0f);
  l.inner_cone = 0.3f;
  l.outer_cone = 0.6f;
  return l;
}

std::vector<VolumePart> volume_parts() {
  const glm::vec3 at(0.25f, 0.5f, -3.0f), origin(0.0f);
  const Light plain = volume_light(KIT_LIGHT_POINT, at, {1.0f, 0.8f, 0.6f}, 2.0f, 10.0f);
  const std::vector<Light> alike = {plain, plain, plain};
  const std::vector<float> radius4 = {4.0f, 4.0f, 4.0f};
  // Away from the camera at the origin, so that every surface facing the light faces it too.
  const glm::vec3 away[] = {{0.0f, 0.0f, -1.0f}, {0.6f, 0.0f, -0.8f}, {-0.6f, 0.0f, -0.8f},
                            {0.0f, 0.6f, -0.8f}, {0.0f, -0.6f, -0.8f}, {0.48f, 0.6f, -0.64f}};
  const auto facing = [&](std::vector<float> distances) {
    std::vector<VolumeTexel> out;
    for (size_t i = 0; i < distances.size(); ++i) out.push_back({away[i % 6], distances[i], 1.0f, {}, static_cast<int>(i)});
    return out;
  };
  const std::vector<VolumeTexel> unit = facing({1, 1, 1, 1, 1, 1});
  std::vector<VolumePart> parts;
  // The camera inside the volume radius: a sphere test made at the camera shows in the sphere's parts alone.
  parts.push_back({"light_volume/view", "view vector",
                   "light 2 of three alike: a point light of 2 cd, range 10, volume radius 16; u_attenuation_model = 0; "
                   "camera at (1.5, 2, 1); each surface 1 m from the light, facing it",
                   alike, {16.0f, 16.0f, 16.0f}, 0, {1.5f, 2.0f, 1.0f}, unit});
  // The cosine: one point 1 m from the light, its normal turned from the light.
  std::vector<VolumeTexel> turned;
  const glm::vec3 across[] = {{1, 0, 0}, {0, 1, 0}, {-1, 0, 0}, {0, -1, 0}, {0.6f, 0.8f, 0}, {-0.8f, 0.6f, 0}};
  const float cosines[] = {1.0f, 0.8f, 0.5f, 0.2f, -0.3f, -0.7f};
  for (int i = 0; i < 6; ++i) turned.push_back({away[0], 1.0f, cosines[i], across[i], i});
  parts.push_back({"light_volume/cosine", "cosine",
                   "light 2 of three alike: a point light of 2 cd, range 10, volume radius 4; u_attenuation_model = 0; "
                   "camera at the origin; one point 1 m from the light, its normal at n.l = 1, 0.8, 0.5, 0.2, -0.3, -0.7",
                   alike, radius4, 0, origin, turned});
  // The falloff: distances across the range, under both models, and a spot's cone.
  const std::vector<Light> ranged(3, volume_light(KIT_LIGHT_POINT, at, {1.0f, 0.8f, 0.6f}, 2.0f, 4.0f));
  const std::vector<VolumeTexel> spread = facing({0.5f, 0.8f, 1.3f, 2.0f, 2.8f, 3.5f});
  // A volume radius past the range (the light is 0 there): a sphere test of d^2 against r
  // does not reach into the falloff's texels.
  const std::vector<float> radius16 = {16.0f, 16.0f, 16.0f};
  parts.push_back({"light_volume/falloff-physical", "falloff",
                   "light 2 of three alike: a point light of 2 cd, range 4, volume radius 16; u_attenuation_model = 0; "
                   "camera at the origin; surfaces 0.5 to 3.5 m from the light, facing it",
                   ranged, radius16, 0, origin, spread});
  parts.push_back({"light_volume/falloff-simple", "falloff",
                   "light 2 of three alike: a point light of 2 cd, range 4, volume radius 16; u_attenuation_model = 1; "
                   "camera at the origin; surfaces 0.5 to 3.5 m from the light, facing it",
                   ranged, radius16, 1, origin, spread});
  const std::vector<Light> spots(3, volume_light(KIT_LIGHT_SPOT, at, {1.0f, 0.8f, 0.6f}, 2.0f, 10.0f));
  std::vector<VolumeTexel> cone;
  const float angles[] = {0.0f, 0.2f, 0.35f, 0.45f, 0.55f, 0.8f};
  for (int i = 0; i < 6; ++i) {
    const float a = angles[i], turn = 1.1f * static_cast<float>(i);
    cone.push_back({{std::sin(a) * std::cos(turn), std::sin(a) * std::sin(turn), -std::cos(a)}, 1.5f, 1.0f, {}, i});
  }
  parts.push_back({"light_volume/falloff-spot", "falloff",
                   "light 2 of three alike: a spot light of 2 cd along -z, cones 0.3 and 0.6 rad, range 10, volume "
                   "radius 4; u_attenuation_model = 0; camera at the origin; surfaces 1.5 m from the light at 0 to 0.8 rad "
                   "off its axis, facing it",
                   spots, radius4, 0, origin, cone});
  // The light read: three different lights, the probe's the third.
  const std::vector<Light> three = {volume_light(KIT_LIGHT_POINT, {-1.5f, 1.0f, -2.0f}, {0.2f, 0.4f, 1.0f}, 5.0f, 10.0f),
                                    volume_light(KIT_LIGHT_SPOT, {1.0f, -0.5f, -2.5f}, {1.0f, 0.3f, 0.2f}, 3.0f, 10.0f), plain};
  parts.push_back({"light_volume/light", "light read",
                   "light 2 of three different lights (v_light = 2): a point light of 2 cd at (0.25, 0.5, -3), range 10, "
                   "volume radius 4; u_attenuation_model = 0; camera at the origin; each surface 1 m from it, facing it",
                   three, radius4, 0, origin, unit});
  // The sphere test: a light whose range is its radius (nothing past it either way), and one
  // without a range, whose volume radius alone says where it ends.
  parts.push_back({"light_volume/sphere-ranged", "sphere test (a ranged light)",
                   "light 2 of three alike: a point light of 2 cd, range 2, volume radius 2; u_attenuation_model = 0; "
                   "camera at the origin; surfaces 0.5, 1.2, 1.5 and 1.9 m from the light (inside) and 2.1 and 2.5 m "
                   "(outside), facing it",
                   std::vector<Light>(3, volume_light(KIT_LIGHT_POINT, at, {1.0f, 0.8f, 0.6f}, 2.0f, 2.0f)),
                   {2.0f, 2.0f, 2.0f}, 0, origin, facing({0.5f, 1.2f, 1.5f, 1.9f, 2.1f, 2.5f})});
  parts.push_back({"light_volume/sphere-unranged", "sphere test",
                   "light 2 of three alike: a point light of 2 cd without a range, volume radius 2.5; "
                   "u_attenuation_model = 0; camera at the origin; surfaces 0.5 to 2.4 m from the light, facing it",
                   std::vector<Light>(3, volume_light(KIT_LIGHT_POINT, at, {1.0f, 0.8f, 0.6f}, 2.0f, 0.0f)),
                   {2.5f, 2.5f, 2.5f}, 0, origin, facing({0.5f, 1.0f, 1.5f, 1.8f, 2.1f, 2.4f})});
  parts.push_back({"light_volume/lookup", "G-buffer lookup",
                   "down a column; light 2 of three alike: a point light of 2 cd, range 10, volume radius 4; "
                   "u_attenuation_model = 0; camera at the origin; each surface 1 m from the light, facing it",
                   alike, radius4, 0, origin, unit, true});
  return parts;
}

// Lab 7's light_volume.frag drawn alone, as light 2's volume would draw it, over six G-buffer
// texels, once per part; each probe sets up the others' terms so that they cannot show:
// every surface faces the light (n.l = 1) from 1 m (lab 3's falloff is the intensity there,
// the range window within 1e-4 of 1), the camera at the origin (a view vector from the
// origin is the right one) and the three lights alike (any index reads the same light):
//   view vector      the camera elsewhere;
//   cosine           the normal turned from the light, past 90 degrees for two texels;
//   falloff          distances across the range under each model, and a spot's cone;
//   light read       three different lights;
//   sphere test      surfaces just inside and just outside a light whose range is its
//                    radius (outside, the light is 0 with or without the optional test), and
//                    inside the volume radius of a light without a range;
//   G-buffer lookup  down a column (every probe's texels are distinct along its row).
std::vector<FunctionProbe> make_lab7() {
  using T = ProbeType;
  std::vector<FunctionProbe> probes;
  for (const VolumePart& part : volume_parts()) {
    FunctionProbe p = pass_probe(7, "light_volume.frag",
                                 {{"u_gbuffer_position", T::Vec3}, {"u_gbuffer_normal", T::Vec3},
                                  {"u_gbuffer_albedo", T::Vec3}, {"u_gbuffer_material", T::Vec3}},
                                 T::Vec3);
    p.id = part.id;
    p.term = part.term;
    p.setting = part.setting;
    p.column = part.column;
    auto setup = std::make_shared<LightVolumeProbeSetup>();
    setup->lights = part.lights;
    setup->volume_radii = part.radii;
    p.light_volume = setup;
    ProbeUniform camera{"u_camera_position"};
    camera.is_vec3 = true;
    camera.vec3 = part.camera;
    p.uniforms = {camera, {"u_attenuation_model", true, static_cast<float>(part.model)}, {"u_probe_light", true, 2.0f}};
    for (const VolumeTexel& t : part.texels) p.cases.push_back(volume_case(part.lights[2].position, t));
    probes.push_back(p);
  }
  return probes;
}

// --- Labs 1 and 4: the geometry pass, one attachment at a time -------------------------------

// A texture for the geometry probes: 4 x 4 texels, each its own colour (RGB from its place,
// alpha 255), or every one `texel`. One size for all: on llvmpipe a texture of another shape
// compiles the fragment shader again (tens of milliseconds for lab 4's).
ImageRgba8 probe_texture(bool distinct, glm::u8vec4 texel = glm::u8vec4(0)) {
  constexpr int side = 4;
  ImageRgba8 image{side, side, std::vector<unsigned char>(static_cast<size_t>(side) * side * 4)};
  for (int y = 0; y < side; ++y)
    for (int x = 0; x < side; ++x) {
      const glm::u8vec4 v = distinct ? glm::u8vec4(40 + 50 * x, 30 + 55 * y, 20 + 13 * (4 * x + y), 255) : texel;
      for (int c = 0; c < 4; ++c) image.pixels[(static_cast<size_t>(y) * side + x) * 4 + c] = v[c];
    }
  return image;
}

// One probe of the geometry pass: the attachment it reads and how it is set up.
struct GeometryPart {
  const char* id;
  const char* term;
  const char* setting;
  int attachment;
  bool alpha = false, back_faces = false, white = false, uv = false, turned = true;
  int alpha_mode = KIT_ALPHA_OPAQUE;
  bool normal_map = false;
};

// The probes of lab `lab`'s geometry pass, in order (lab 4 adds its normal map's).
std::vector<GeometryPart> geometry_parts(int lab) {
  std::vector<GeometryPart> parts = {
      {"gbuffer/position", "position", "out_position.xyz; a rotated, unevenly scaled model seen by a turned camera", KIT_GBUF_POSITION},
      {"gbuffer/normal", "normal", "out_normal.xyz; a rotated, unevenly scaled model seen by a turned camera", KIT_GBUF_NORMAL},
      {"gbuffer/back-face", "back face", "out_normal.xyz; a double-sided material seen from behind", KIT_GBUF_NORMAL, false, true},
      {"gbuffer/base-colour", "base colour",
       "out_albedo.rgb; u_base_color_factor (0.8, 0.6, 0.4, 0.9), a base colour texture uniformly (200, 150, 100, 153)",
       KIT_GBUF_ALBEDO},
      {"gbuffer/alpha", "alpha",
       "out_albedo.a; MASK at 0.5, u_base_color_factor (0.8, 0.6, 0.4, 0.9), a base colour texture uniformly (200, 150, 100, 153); 0 where no surface is written",
       KIT_GBUF_ALBEDO, true, false, false, false, true, KIT_ALPHA_MASK},
      {"gbuffer/metallic-roughness", "metallic-roughness",
       "out_material.rgb; u_metallic_factor 0.7, u_roughness_factor 0.9, a metallic-roughness texture uniformly (60, 100, 200)",
       KIT_GBUF_MATERIAL},
      {"gbuffer/emission", "emission",
       "out_emission.rgb; u_emissive_factor (2, 1.5, 0.5), an emissive texture uniformly (180, 120, 60)", KIT_GBUF_EMISSION},
      {"gbuffer/uv-albedo", "texture coordinates",
       "out_albedo.rgb; textures of 4 x 4 distinct texels, each at its own UV slot and offset; factors 1, vertex colours white; the model and camera untransformed",
       KIT_GBUF_ALBEDO, false, false, true, true, false},
      {"gbuffer/uv-material", "texture coordinates",
       "out_material.rgb; textures of 4 x 4 distinct texels, each at its own UV slot and offset; factors 1, vertex colours white; the model and camera untransformed",
       KIT_GBUF_MATERIAL, false, false, true, true, false},
      {"gbuffer/uv-emission", "texture coordinates",
       "out_emission.rgb; textures of 4 x 4 distinct texels, each at its own UV slot and offset; factors 1, vertex colours white; the model and camera untransformed",
       KIT_GBUF_EMISSION, false, false, true, true, false},
  };
  if (lab == 4) {
    parts.push_back({"gbuffer/normal-map", "normal map",
                     "out_normal.xyz; a normal map uniformly (180, 100, 230), scale 0.8; the model and camera untransformed",
                     KIT_GBUF_NORMAL, false, false, false, false, false});
    parts.back().normal_map = true;
    parts.push_back({"gbuffer/tangent-frame", "tangent frame",
                     "out_normal.xyz; a normal map uniformly (180, 100, 230), scale 0.8; a rotated, unevenly scaled model seen by a turned camera",
                     KIT_GBUF_NORMAL});
    parts.back().normal_map = true;
    parts.push_back({"gbuffer/uv-normal", "texture coordinates",
                     "out_normal.xyz; textures of 4 x 4 distinct texels, each at its own UV slot and offset; factors 1, vertex colours white; the model and camera untransformed",
                     KIT_GBUF_NORMAL, false, false, true, true, false});
    parts.back().normal_map = true;
  }
  return parts;
}

// What `part`'s probe draws with: its transforms, textures and material.
std::shared_ptr<GeometryProbeSetup> geometry_setup(const GeometryPart& part) {
  const glm::mat4 turned_model =
      glm::translate(glm::mat4(1.0f), glm::vec3(0.5f, -0.25f, 0.3f)) *
      glm::rotate(glm::mat4(1.0f), 0.6f, glm::normalize(glm::vec3(0.3f, 1.0f, 0.2f))) *
      glm::scale(glm::mat4(1.0f), glm::vec3(1.5f, 0.5f, 1.0f));
  const glm::mat4 turned_view = glm::lookAt(glm::vec3(0.4f, 0.3f, 2.0f), glm::vec3(0.0f), glm::vec3(0.0f, 1.0f, 0.0f));
  // The plain materials' one-texel textures, and the texture-coordinate probes' offsets.
  const glm::u8vec4 base_texel(200, 150, 100, 153), mr_texel(60, 100, 200, 255), emissive_texel(180, 120, 60, 255),
      normal_texel(180, 100, 230, 255);
  auto setup = std::make_shared<GeometryProbeSetup>();
  setup->attachment = part.attachment;
  setup->alpha = part.alpha;
  setup->back_faces = part.back_faces;
  if (part.turned) {
    setup->model = turned_model;
    setup->view = turned_view;
  }
  Material& m = setup->material;
  m.alpha_mode = part.alpha_mode;
  m.double_sided = part.back_faces;
  if (part.uv) {
    for (int unit = 0; unit < kMaterialTextureCount; ++unit) setup->images.push_back(probe_texture(true));
    const glm::vec2 offsets[] = {{0.25f, 0.0f}, {0.5f, 0.25f}, {0.0f, 0.5f}, {0.75f, 0.25f}};  // by unit
    for (int unit = 0; unit < kMaterialTextureCount; ++unit) {
      m.texture(unit).uv.slot = unit == KIT_UNIT_NORMAL_MAP || unit == KIT_UNIT_EMISSIVE ? 1 : 0;
      m.texture(unit).uv.transform = texture_transform_matrix(offsets[unit], 0.0f, glm::vec2(1.0f));
    }
    m.emissive = glm::vec3(1.0f);
  } else {
    setup->images = {probe_texture(false, base_texel), probe_texture(false, mr_texel), probe_texture(false, normal_texel),
                     probe_texture(false, emissive_texel)};
    m.base_color_factor = glm::vec4(0.8f, 0.6f, 0.4f, 0.9f);
    m.metallic_factor = 0.7f;
    m.roughness_factor = 0.9f;
    m.emissive = glm::vec3(2.0f, 1.5f, 0.5f);
    m.normal_scale = 0.8f;
  }
  for (int unit = 0; unit < kMaterialTextureCount; ++unit) {
    m.texture(unit).image = unit;
    m.texture(unit).sampler = 0;
  }
  if (!part.normal_map) m.texture(KIT_UNIT_NORMAL_MAP).image = -1;
  return setup;
}

// `part`'s cases: each a vertex's attributes.
std::vector<ProbeCase> geometry_cases(const GeometryPart& part) {
  struct Attributes {
    glm::vec3 normal;
    glm::vec4 tangent, color;
    glm::vec2 uv0, uv1;
  };
  const Attributes cases[] = {
      {{0.2f, 0.3f, 1.2f}, {1.0f, 0.0f, 0.1f, 1.0f}, {1.0f, 0.8f, 0.6f, 1.0f}, {0.125f, 0.375f}, {0.375f, 0.125f}},
      {{-0.5f, 0.1f, 0.9f}, {0.9f, 0.3f, 0.0f, -1.0f}, {0.5f, 1.0f, 0.75f, 0.8f}, {0.625f, 0.125f}, {0.875f, 0.375f}},
      {{0.4f, -0.6f, 0.8f}, {1.0f, 0.2f, -0.3f, 1.0f}, {0.9f, 0.4f, 1.0f, 0.95f}, {0.875f, 0.625f}, {0.125f, 0.625f}},
      {{0.0f, 0.0f, 1.5f}, {0.8f, -0.5f, 0.2f, -1.0f}, {0.3f, 0.6f, 0.9f, 0.5f}, {0.375f, 0.875f}, {0.625f, 0.875f}},
      {{-0.3f, -0.4f, 0.6f}, {0.6f, 0.7f, 0.1f, 1.0f}, {1.0f, 1.0f, 1.0f, 1.0f}, {0.125f, 0.875f}, {0.375f, 0.625f}},
      {{0.7f, 0.2f, 0.5f}, {1.0f, -0.1f, 0.4f, -1.0f}, {0.7f, 0.9f, 0.2f, 0.7f}, {0.625f, 0.625f}, {0.875f, 0.875f}},
  };
  std::vector<ProbeCase> out;
  for (const Attributes& a : cases) {
    ProbeCase c;
    push(c.inputs, a.normal);
    // Mirrored tangents only where the frame is under test: elsewhere the handedness
    // would show as a decode mistake would.
    const float w = part.turned ? a.tangent.w : 1.0f;
    for (float v : {a.tangent.x, a.tangent.y, a.tangent.z, w}) push(c.inputs, v);
    for (float v : {a.uv0.x, a.uv0.y, a.uv1.x, a.uv1.y}) push(c.inputs, v);
    const glm::vec4 color = part.white ? glm::vec4(1.0f) : a.color;
    for (float v : {color.x, color.y, color.z, color.w}) push(c.inputs, v);
    out.push_back(c);
  }
  return out;
}

// Labs 1 and 4's geometry pass (gbuffer.vert and gbuffer.frag) drawn alone, one probe per
// attachment and material, each set up so that one part of the pass shows:
//   position, normal      a rotated, unevenly scaled model seen by a turned camera;
//   back face             a double-sided material seen from behind;
//   base colour           a factor, a uniform texture and the vertex colours (not the alpha);
//   alpha                 a MASK material whose cases lie on both sides of the cutoff;
//   metallic-roughness    factors and a uniform texture of distinct R, G and B;
//   emission              a factor, a uniform texture, and a base colour to leave out of it;
//   texture coordinates   every texture 4 x 4 texels of distinct colours, each read at its
//                         own UV slot and offset, factors 1 and white vertex colours, the
//                         model and camera untransformed: only where each texture is
//                         sampled shows (one probe per attachment);
//   normal map (lab 4)    a uniform tilted texel, its scale 0.8, the model and camera untransformed;
//   tangent frame (lab 4) the same under the rotated, unevenly scaled model and a turned
//                         camera, and half the tangents mirrored (w = -1): only there do the
//                         frame's transforms and handedness show.
// Every UV lies at a texel's centre, offsets are whole texels, and the textures are sampled
// nearest: a texel's value is exact, whatever the filtering.
std::vector<FunctionProbe> make_geometry(int lab) {
  using T = ProbeType;
  std::vector<FunctionProbe> probes;
  for (const GeometryPart& part : geometry_parts(lab)) {
    FunctionProbe p = pass_probe(lab, "gbuffer.frag",
                               {{"a_normal", T::Vec3}, {"a_tangent", T::Vec4}, {"a_texcoord0", T::Vec2},
                                {"a_texcoord1", T::Vec2}, {"a_color", T::Vec4}},
                               part.alpha ? T::Float : T::Vec3);
    // Unique over the kit: lab 4's are "normalmap/...".
    p.id = lab == 4 ? "normalmap/" + std::string(part.id).substr(std::string("gbuffer/").size()) : part.id;
    p.srgb_decoded = !part.alpha && (part.attachment == KIT_GBUF_ALBEDO || part.attachment == KIT_GBUF_EMISSION);
    p.term = part.term;
    p.setting = part.setting;
    p.geometry = geometry_setup(part);
    p.cases = geometry_cases(part);
    probes.push_back(p);
  }
  return probes;
}

}  // namespace

std::vector<FunctionProbe> pass_probes(int lab) {
  switch (lab) {
    case 1: return make_geometry(1);
    case 4: return make_geometry(4);
    case 5: return make_lab5();
    case 6: return make_lab6();
    case 7: return make_lab7();
    default: return {};
  }
}

FrameCamera geometry_probe_camera(const glm::mat4& view) {
  FrameCamera camera;
  camera.view = view;
  camera.znear = 0.0f;
  camera.zfar = 2.0f;
  camera.projection = glm::ortho(-1.0f, 1.0f, -1.0f, 1.0f, camera.znear, camera.zfar);
  camera.position = glm::vec3(glm::inverse(view)[3]);
  return camera;
}

glm::vec3 geometry_probe_view_point(int index, int count) {
  return glm::vec3(-1.0f + (2.0f * static_cast<float>(index) + 1.0f) / static_cast<float>(count), 0.0f, -1.0f);
}

Vertex geometry_probe_vertex(const std::vector<float>& in) {
  Vertex v{};
  v.normal = glm::vec3(in.at(0), in.at(1), in.at(2));
  v.tangent = glm::vec4(in.at(3), in.at(4), in.at(5), in.at(6));
  v.texcoord = glm::vec2(in.at(7), in.at(8));
  v.texcoord1 = glm::vec2(in.at(9), in.at(10));
  for (int c = 0; c < 4; ++c) v.color[c] = vertex_color_component(in.at(11 + static_cast<size_t>(c)));
  return v;
}

}  // namespace kit::grade
