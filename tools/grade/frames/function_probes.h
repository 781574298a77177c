#pragma once
// Function probes: where a lab's starter declares functions with fixed signatures (lab 2's
// BRDF terms, lab 3's falloff and tone map), or its files are whole passes (lab 5's bright
// pass, blur and composite, each drawn alone on a few texels), the grader's render worker evaluates the
// submission's functions at fixed inputs in a small off-screen pass (probe_pass.h) and the
// grader compares the values with the reference solution's, made with the references
// (`--update-references` writes them to references/probes.json, as numbers: no formula
// of a lab enters a student copy). A probe only informs: scores stay the images' and the
// work counts'. The feedback names the function, the first inputs where it differs, its
// value and the expected one, how many inputs differ and the shape of the difference
// where one fits (a constant factor, an offset, a sign, a square, swapped arguments,
// only where an argument is 0 or 1).
#include <glm/glm.hpp>
#include <nlohmann/json_fwd.hpp>

#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "images/image_io.h"     // ImageRgba8
#include "render/renderer.h"     // FrameCamera
#include "scene/scene.h"         // Light, Material, Vertex

namespace kit::grade {

enum class ProbeType { Float, Vec2, Vec3, Vec4, Light };

struct ProbeArgument {
  std::string name;  // as the starter's signature names it
  ProbeType type;
};

// A uniform the probed functions read, set for the whole probe (lab 3's falloff model, gamma;
// lab 6's camera, a vec3).
struct ProbeUniform {
  std::string name;
  bool integer = false;
  float value = 0.0f;
  bool is_vec3 = false;
  glm::vec3 vec3{0.0f};
};

// A map a pass probe's file samples by direction or by table coordinates (lab 6's irradiance
// map, prefiltered map and BRDF table), filled so that what the pass looks up shows in its
// value: the same value everywhere, or each texel its own texture coordinates.
struct ProbeMap {
  enum class Fill {
    Uniform,      // `value` at every texel of every level
    Coordinates,  // (s, t, value.z): a texel's centre coordinates, at every level (bilinear returns the coordinates looked up)
    Levels,       // value (1 + k) at every texel of level k (trilinear between whole levels returns value (1 + level))
  };
  std::string sampler;  // "u_irradiance", "u_prefiltered", "u_brdf_lut"
  Fill fill = Fill::Uniform;
  glm::vec3 value{0.0f};
};

// A geometry pass probe (labs 1 and 4, FunctionProbe::geometry): the lab's gbuffer.vert and
// gbuffer.frag draw one quad per case through the framework's own draw (draw_item), each
// quad covering its texel of a row, every vertex of it the case's attributes (so every
// fragment gets them unchanged), and one attachment of the G-buffer is read back.
struct GeometryProbeSetup {
  int attachment = 0;      // KIT_GBUF_*: the attachment read
  bool alpha = false;      // its alpha (a Float probe), else its rgb
  glm::mat4 model{1.0f};   // every quad's world matrix
  glm::mat4 view{1.0f};    // the camera's; its projection is orthographic, so that a
                           // texel's world position is the quad's at its centre exactly
  bool back_faces = false; // the quads seen from behind (a double-sided material's back)
  Material material;       // its textures index `images`, each sampled nearest, repeating
  std::vector<ImageRgba8> images;
};

// A geometry probe's camera: `view`, and an orthographic projection of x and y in [-1, 1]
// and z in [-2, 0] of view space (looking down -z) onto the row of texels.
FrameCamera geometry_probe_camera(const glm::mat4& view);
// Where case `index` of `count` lies: the view-space point its quad shows at its texel's
// centre (y = 0, z = -1, x from -1 to 1 across the row). A geometry probe's quad is made
// around it in the plane z = -1 of view space.
glm::vec3 geometry_probe_view_point(int index, int count);
// A geometry probe case's vertex attributes (a_position aside): a_normal, a_tangent,
// a_texcoord0, a_texcoord1, a_color, as the case's inputs hold them.
Vertex geometry_probe_vertex(const std::vector<float>& inputs);

// Lab 7's pass probe (FunctionProbe::light_volume): light_volume.frag drawn as one light's
// volume would draw it, over a row of G-buffer texels: the lights kit_light reads (the
// framework's uniform block, each with its volume radius), and the vertex stage
// probe_light_volume.vert, which covers the row and hands every fragment v_light =
// u_probe_light (a ProbeUniform).
struct LightVolumeProbeSetup {
  std::vector<Light> lights;
  std::vector<float> volume_radii;  // one per light
};

struct ProbeCase {
  std::vector<float> inputs;  // the arguments' floats in order (a Light as function_probe_inputs.glsl reads it)
  // Where the kit's own guard decides the value (a denominator at 0: a light at the point,
  // a surface seen or lit edge-on), a correct function may guard with another floor: only
  // a finite value is asked for.
  bool finite_only = false;
};

struct FunctionProbe {
  std::string id;        // unique over the kit: "distribution_ggx", "light_radiance/simple"
  int lab = 0;
  std::string file;      // the lab file that declares it: "brdf.glsl"
  std::string function;  // "distribution_ggx"
  std::string setting;   // "" or what the uniforms are set to, in words: "u_attenuation_model = 1"
  std::string shader;    // the probe shader that calls it: "probe_brdf.frag"
  int index = 0;         // u_probe_function: its branch in the shader
  std::string define;    // the #if that holds its call: "KIT_PROBE_DISTRIBUTION_GGX"
  std::vector<ProbeArgument> arguments;
  ProbeType result = ProbeType::Float;
  std::vector<ProbeUniform> uniforms;
  std::vector<ProbeCase> cases;
  // A pass probe (lab 5, whose files are whole passes): the lab's own `file` drawn with
  // fullscreen.vert over one texel per case, each argument a sampler it reads (u_hdr, u_bloom)
  // holding the case's value at that texel; down a column where `column` (a vertical blur).
  // Its function is "main". Lab 6's ibl.frag reads the G-buffer the same way, and `maps`.
  bool pass = false;
  bool column = false;
  std::vector<ProbeMap> maps;
  // What a pass probe isolates, where its file holds more than one term (lab 6: "diffuse",
  // "directions"): its part is then "FILE, TERM", and naming tells the terms apart.
  std::string term;
  // A term probe (lab 2's cook_torrance, lab 3's light_radiance): the function at inputs that
  // take its terms apart (a metal, a black dielectric, l = v), read where the functions it
  // calls, `given`, agree and the function's own probe differs: the decision names the term
  // that differs and how (term_probes.h). Where one given function differs, that explains it,
  // and the term it is ("fresnel_schlick": "fresnel") is the term that differs.
  std::map<std::string, std::string> given;
  // A term probe of its own cases ("cook_torrance/terms"), reported only through its decision,
  // else the function's own probe read term by term too (lab 3's light_radiance).
  bool terms_only = false;
  // A geometry pass probe (labs 1 and 4): its arguments are vertex attributes.
  std::shared_ptr<const GeometryProbeSetup> geometry;
  // Lab 7's light_volume.frag: the lights it reads and its vertex stage.
  std::shared_ptr<const LightVolumeProbeSetup> light_volume;
  // Its values went through an 8-bit sRGB texel's decode, which GL lets an implementation
  // approximate (llvmpipe's is 0.17 % low at 200/255): compared within 1 %, or 2e-3 of the
  // largest expected value where that is more, instead of 0.2 %.
  bool srgb_decoded = false;
  std::string title() const;  // "distribution_ggx", "light_radiance (u_attenuation_model = 1)", "bright.frag (...)"
  std::string part() const;   // what holds a difference, for naming: the function, a pass's file, or "FILE, TERM"
};

// A value as the probes' messages write it: 4 significant digits.
std::string probe_number(double v);

// Floats one case of a probe holds at most: the probe shaders read KIT_PROBE_TEXELS texels.
constexpr int kProbeTexels = 6;

// Every probe of lab `lab` (none for a lab whose starter fixes no signature).
const std::vector<FunctionProbe>& function_probes(int lab);
const std::vector<FunctionProbe>& all_function_probes();

// What a render worker got from one probe: the values, one vec4 per case (a float result in
// .x), or why it could not run (the file does not declare the function, or does not compile).
struct ProbeValues {
  std::vector<glm::vec4> values;
  std::string error;
};

// A render worker's probe values as child.json holds them, and back.
nlohmann::json probe_values_json(const ProbeValues& values);
ProbeValues probe_values_from_json(const nlohmann::json& json);

// references/probes.json: each probe's inputs and the reference solution's values.
nlohmann::json probes_reference_json(const std::vector<std::pair<const FunctionProbe*, ProbeValues>>& expected);
// <dir>/probes.json, the references' (null when it is not there or cannot be read), and
// writing it (unless it holds that text already; returns its name when written).
nlohmann::json read_probes_reference(const std::filesystem::path& dir);
std::vector<std::string> write_probes_reference(const std::filesystem::path& dir, const nlohmann::json& probes);

// The probes of lab `lab` as a grading run probes them: at the inputs probes.json holds
// where it holds the probe (so the expected values are those of the very inputs drawn,
// whatever libm made the table's on this machine), else at the table's.
std::vector<FunctionProbe> probes_to_run(int lab, const nlohmann::json& reference);
// The expected values of `probe` from probes.json; empty when the file lacks the probe or
// holds other inputs than the probe's (beyond float rounding: stale, --update-references
// makes it again).
std::vector<glm::vec4> expected_probe_values(const nlohmann::json& reference, const FunctionProbe& probe);
// Differences between probes.json and the table, in words (empty when they agree).
std::vector<std::string> probes_reference_differences(const nlohmann::json& reference);

struct ProbeOutcome {
  const FunctionProbe* probe = nullptr;
  std::string status;   // kProbeAgrees, kProbeDiffers or kProbeNotRun
  int differing = 0, total = 0;
  std::string first;    // "distribution_ggx(n_dot_h = 0.95, alpha = 0.09) = 0.318, expected 10.46"
  std::string shape;    // "each by a factor of 3.14 (pi)", or ""
  std::string message;  // the line a report prints
  // What holds the difference, for naming: the probe's part (FunctionProbe::part), or a term
  // probe's decided term ("cook_torrance, fresnel": term_probes.h).
  std::string part;
};
constexpr const char* kProbeAgrees = "agrees";
constexpr const char* kProbeDiffers = "differs";
constexpr const char* kProbeNotRun = "not_run";  // not declared, or no expected values
// A term probe that differs where a function it calls (FunctionProbe::given) differs too:
// that function's own probe says where; its part is that function's term where one differs.
constexpr const char* kProbeExplained = "explained";

// Compares a submission's values at `probe`'s inputs (probes_to_run) with the expected ones (relative 2e-3, where a value is
// compared at all) and words the difference.
ProbeOutcome compare_probe(const FunctionProbe& probe, const ProbeValues& got, const std::vector<glm::vec4>& expected);
nlohmann::json probe_outcome_json(const ProbeOutcome& outcome);

// Lab `lab`'s probes (probes_to_run) from a render worker's child.json ("probes") against
// probes.json, in the table's order (empty for a lab without probes).
std::vector<ProbeOutcome> probe_outcomes(int lab, const nlohmann::json& child, const nlohmann::json& reference);

// What a report says of a lab's probes: a line for each function that differs ("Your
// function ..."), or, where every one agrees and `a_check_failed`, that the mistake lies
// where they are called. Empty otherwise.
std::vector<std::string> probe_feedback(const std::vector<ProbeOutcome>& probes, bool a_check_failed);

}  // namespace kit::grade
