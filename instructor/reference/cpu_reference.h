#pragma once
// CPU reference for the shading of labs 2-5, evaluated in double precision.
//
// Every function here mirrors one shader function and says which; the guards
// are the constants of shaders/guards.glsl under the same names. Tests evaluate
// it on the renderer's read-back G-buffer to check the GPU numerically
// (instructor/tests/test_lab_equations.cpp), and evaluate it with guards switched off to
// show what each guard prevents (instructor/tests/test_stability.cpp).
//
// What mirrors what:
//   Lab 2  solutions/02-lighting/brdf.glsl      fresnel_schlick, distribution_ggx,
//                                               the geometric term, cook_torrance
//          solutions/02-lighting/lighting.frag  shade, shade_gbuffer
//          shaders/attenuation.glsl             light_radiance with stage 2
//          shaders/tonemap.glsl                 display with stage 2 (clamp)
//   Lab 3  solutions/03-attenuation/*.glsl      spot_cone_factor, light_radiance, tonemap
//   Lab 1  solutions/01-gbuffer/gbuffer.*       base_color, vertex_color (and lab 4's copy)
//   Lab 4  solutions/04-normalmap/gbuffer.*     world_tangent_frame, mapped_normal
//          geometry_pass.cpp (u_normal_matrix)  normal_matrix
//   Lab 5  solutions/05-postprocess/*.frag      bright_pass, blur_pass, bloom, composite
//                                               (the custom effect is left out: identity when off)
//   Lab 7  solutions/07-lightvolumes/*          light_volume_term; shade() per light: a volume adds lab 2's term of its
//                                               light (test_light_volumes.cpp; ranged lights cut at
//                                               their range lose nothing)
//   frame_lights.cpp light_flux and light_texture  exact_light_flux, uploaded_light, exact_light
//
// Images follow image_io.h: rows top-down, RGBA floats. Values are computed in
// double and stored as float (a relative change of at most 6e-8).
#include <glm/glm.hpp>

#include <functional>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "images/image_io.h"
#include "render/renderer.h"
#include "scene/scene.h"

namespace kit::reference {

using glm::dmat3;
using glm::dmat4;
using glm::dvec3;
using glm::dvec4;

// --- Constants the shaders define, under the shaders' names --------------------
// shaders/guards.glsl (each is explained there).
constexpr double KIT_MIN_N_DOT_V = 1e-4;
constexpr double KIT_MIN_N_DOT_L = 1e-4;
constexpr double KIT_MIN_V_DOT_H = 1e-4;
constexpr double KIT_MIN_ROUGHNESS = 0.045;
constexpr double KIT_MIN_DENOMINATOR = 1e-7;
constexpr double KIT_MIN_GGX_DENOMINATOR = 1e-12;
constexpr double KIT_MIN_DISTANCE_SQUARED = 1e-4;
constexpr double KIT_MIN_CONE_COS_GAP = 1e-4;
constexpr double KIT_MIN_SPOT_SOLID_ANGLE = 1e-6;
constexpr double KIT_HDR_MAX = 65504.0;
// Below this squared length a tangent-frame vector (lab 4) is degenerate and replaced.
constexpr double KIT_MIN_TANGENT_LENGTH_SQUARED = 1e-12;
// shaders/math.glsl
constexpr double KIT_PI = 3.14159265358979323846;
constexpr double KIT_LUMINANCE[3] = {0.2126, 0.7152, 0.0722};
// solutions/05-postprocess/blur.frag: centre weight, then offsets 1..4.
constexpr double KIT_BLUR_WEIGHTS[5] = {0.227027, 0.1945946, 0.1216216, 0.054054, 0.016216};

// One mirrored constant, so a test can check the shader text still says the same.
struct MirroredConstant {
  const char* name;            // as spelled in the shader
  const char* file;            // relative to the kit root
  std::vector<double> values;  // one for a scalar, several for a vector or array
};
const std::vector<MirroredConstant>& mirrored_constants();

// --- The HDR target's storage ---------------------------------------------------
// RGBA16F: 10 explicit mantissa bits, smallest normal 2^-14. Below it the step is
// a constant 2^-24, so relative precision is lost; comparisons in linear HDR
// measure error relative to max(|value|, kHalfMinNormal).
constexpr double kHalfMinNormal = 6.103515625e-05;  // 2^-14
// `value` rounded to the nearest binary16 (ties to even); beyond KIT_HDR_MAX it
// becomes +-Inf.
double round_to_half(double value);
// The two binary16 values around `value` (equal when it is one). How a GPU rounds
// a fragment's output into an RGBA16F target is up to the implementation
// (llvmpipe truncates towards zero, others round to nearest), so a stored value is
// either neighbour of the exact one.
struct HalfNeighbours {
  double below, above;
};
HalfNeighbours half_neighbours(double value);

// --- Guards ---------------------------------------------------------------------
// Every floor and clamp the shading takes from guards.glsl (lab 4's tangent guard
// among them). The defaults are the kit's; none() switches every one off, which
// turns each formula into its naive textbook form: a floor of -Inf is no floor
// (max(x, -Inf) == x), a ceiling of +Inf no ceiling. Tests switch single guards
// off to evaluate the naive formula with the same code.
struct Guards {
  double min_n_dot_v = KIT_MIN_N_DOT_V;
  double min_n_dot_l = KIT_MIN_N_DOT_L;
  double min_v_dot_h = KIT_MIN_V_DOT_H;
  double min_roughness = KIT_MIN_ROUGHNESS;
  double min_denominator = KIT_MIN_DENOMINATOR;
  double min_ggx_denominator = KIT_MIN_GGX_DENOMINATOR;
  double min_distance_squared = KIT_MIN_DISTANCE_SQUARED;
  double min_cone_cos_gap = KIT_MIN_CONE_COS_GAP;
  double min_spot_solid_angle = KIT_MIN_SPOT_SOLID_ANGLE;
  double hdr_max = KIT_HDR_MAX;
  double min_tangent_length_squared = KIT_MIN_TANGENT_LENGTH_SQUARED;
  bool bright_pass_drops_non_finite = true;  // bright.frag's isnan/isinf test
  static Guards none();
};

// --- Inputs -----------------------------------------------------------------------
// One G-buffer texel as the lighting pass reads it (layout in gbuffer_layout.h).
struct SurfaceSample {
  dvec3 position{0.0};
  dvec3 normal{0.0, 0.0, 1.0};  // normalised by shade(), as lighting.frag does
  dvec3 albedo{0.0};
  double metallic = 0.0;
  double roughness = 1.0;       // perceptual (glTF) roughness
  dvec3 emission{0.0};          // emitted radiance L_e (emissive factor x strength x texel)
  bool covered = false;         // coverage mask: false shades as the clear colour
};

// The RenderSettings the shading depends on, for one stage.
struct ShadingSettings {
  int stage = 3;                     // 2: no falloff, clamp display; 3-5: falloff, Reinhard; 5: bloom
  double gamma = 2.2;                // u_gamma (stage 3 on)
  int attenuation_model = 0;         // u_attenuation_model: 0 physical, 1 simple 1/(1+d^2)
  dvec3 clear_color{0.02, 0.02, 0.025};
  bool postprocess = true;           // stage 5: bloom on
  double bloom_threshold = 1.0;      // stage 5: bright-pass luminance threshold
  int blur_passes = 6;               // stage 5: separable passes, horizontal first
  Guards guards;                     // the kit's; tests switch single ones off
};
// `settings` as the renderer uses them for stage number `stage` (>= 2).
ShadingSettings shading_settings(const RenderSettings& settings, int stage);

// A light as the lighting pass sees it: one row of the light texture (lights.glsl).
struct ShadingLight {
  int type = 0;  // KIT_LIGHT_POINT, KIT_LIGHT_SPOT or KIT_LIGHT_DIRECTIONAL
  dvec3 position{0.0};
  dvec3 direction{0.0, 0.0, -1.0};  // a directional light's light travels along it (l = -direction)
  dvec3 color{1.0};
  double intensity = 1.0;  // candela; lux for a directional light
  double range = 0.0;      // glTF range, 0 = unlimited (stage 3 on: range_window)
  double cos_inner = 1.0;
  double cos_outer = 0.0;
  double flux = 0.0;
};
// frame_lights.cpp light_flux in double (a distinct name: kit::light_flux is found by
// argument-dependent lookup on Light): 4 pi I (point), 2 pi (1 - (cos_i + cos_o)/2) I (spot),
// 0 (directional: no finite flux, and no shader uses it).
double exact_light_flux(const Light& light);
// Cosines and flux in double: the light as the equations define it.
ShadingLight exact_light(const Light& light);
// The light exactly as light_texture uploads it: cosines and flux computed in
// float, then widened. shade() uses this by default, so the reference sees what
// the GPU sees (a cone narrower than float resolution has cos == 1 there).
ShadingLight uploaded_light(const Light& light);
std::vector<ShadingLight> uploaded_lights(const std::vector<Light>& lights);
// The lights a Renderer uploads for `scene`: its own, then spawned_lights.
std::vector<Light> frame_lights(const Scene& scene, const RenderSettings& settings);

// --- Lab 2: BRDF (solutions/02-lighting/brdf.glsl) ----------------------------------
dvec3 fresnel_schlick(double v_dot_h, dvec3 f0);
double distribution_ggx(double n_dot_h, double alpha, const Guards& guards = {});
// The geometric term is cpu_reference.cpp's own: cook_torrance and probe_functions() call it,
// so a course that changes lab 2's G changes that file alone.
// f(p, wo, wi) for unit n, v, l, with the guards of brdf.glsl.
dvec3 cook_torrance(dvec3 n, dvec3 v, dvec3 l, dvec3 albedo, double metallic, double perceptual_roughness,
                    const Guards& guards = {});

// --- Lab 3: attenuation (solutions/03-attenuation/attenuation.glsl) --------------------
// 0 outside the outer cone, 1 inside the inner cone, smoothstep in between.
double spot_cone_factor(const ShadingLight& light, dvec3 p, const Guards& guards = {});
// Radiance arriving at p: stage 2 mirrors shaders/attenuation.glsl (no falloff,
// hard outer cone), stage 3 on mirrors solutions/03-attenuation/attenuation.glsl. A
// directional light gives colour * intensity at every stage (no falloff, cone or range).
dvec3 light_radiance(const ShadingLight& light, dvec3 p, const ShadingSettings& settings);

// --- Lighting pass (solutions/02-lighting/lighting.frag) --------------------------------
// Linear HDR radiance towards the camera, clamped to guards.hdr_max like the shader.
dvec3 shade(const SurfaceSample& surface, const dvec3& camera_position, const std::vector<ShadingLight>& lights,
            const ShadingSettings& settings);
// The same with lights as the renderer uploads them (uploaded_lights).
dvec3 shade(const SurfaceSample& surface, const dvec3& camera_position, const std::vector<Light>& lights,
            const ShadingSettings& settings);

// --- Lab 7 (solutions/07-lightvolumes/light_volume.frag) --------------------------------------
// One light's term at a surface its volume covers: lab 2's term of that light alone, as shade()
// adds it (no emission), 0 where no surface is or where the surface lies outside the light's
// sphere of radius `volume_radius` (where the light adds less than its cut-off; the handout's
// test is optional, so the grader's probe puts no surface outside a sphere that the light
// still reaches).
dvec3 light_volume_term(const SurfaceSample& surface, const dvec3& camera_position, const ShadingLight& light,
                        double volume_radius, const ShadingSettings& settings);

// --- The labs' contracts (tools/grade/lab_functions.json) ------------------------------
// A probed function's arguments as the grader's probe shaders read them, in the order of its
// signature (function_probe_inputs.glsl): floats, vec3s, and Lights as the light texture
// holds them.
class ProbeArguments {
 public:
  explicit ProbeArguments(const std::vector<float>& in) : in_(in) {}
  double scalar() { return in_.at(at_++); }
  dvec3 vec3();
  ShadingLight light();

 private:
  const std::vector<float>& in_;
  size_t at_ = 0;
};
// The function's value (a float's in x) at `arguments`, under the probe's uniforms
// (`settings`: u_attenuation_model, u_gamma).
using ProbeFunction = std::function<dvec3(ProbeArguments& arguments, const ShadingSettings& settings)>;
// Every function a lab's contract lists, by its name there, evaluated by the functions above:
// the tests hold the grader's probe values against these (instructor/tests/test_function_probes.cpp).
// A course that renames, adds or changes a lab function changes its entry here with it.
const std::map<std::string, ProbeFunction>& probe_functions();

// --- Display -------------------------------------------------------------------------
// solutions/03-attenuation/tonemap.glsl: Reinhard c/(c+1) on max(c, 0), then pow(1/gamma).
dvec3 tonemap(dvec3 hdr, double gamma);
// The stage's display mapping: clamp to [0,1] at stage 2 (shaders/tonemap.glsl), tonemap after.
dvec3 display(dvec3 hdr, const ShadingSettings& settings);

// --- Whole frames -----------------------------------------------------------------------
// The G-buffer attachments as read back with Renderer::read_view(view, raw = true).
struct GBufferImages {
  Image position, normal, albedo, material, emission;
};
GBufferImages read_gbuffer(Renderer& renderer);
// A pixel's RGB in double.
dvec3 pixel_rgb(const Image& image, int x, int y);
SurfaceSample gbuffer_sample(const GBufferImages& gbuffer, int x, int y);
// The pixels (x, y) gbuffer_sample calls covered, row by row from the top.
std::vector<std::pair<int, int>> covered_pixels(const GBufferImages& gbuffer);
// The lighting pass over a whole G-buffer: RGBA, alpha 1, as the HDR target holds it
// (before fp16 rounding).
Image shade_gbuffer(const GBufferImages& gbuffer, const dvec3& camera_position, const std::vector<ShadingLight>& lights,
                    const ShadingSettings& settings);
// The stage's output image from the HDR image: display() per pixel before stage 5,
// bloom and composite at stage 5.
Image final_image(const Image& hdr, const ShadingSettings& settings);

// --- Lab 4: normal mapping (solutions/04-normalmap/gbuffer.vert and .frag) -----------------
// u_normal_matrix: the inverse transpose of the model matrix's upper 3x3.
dmat3 normal_matrix(const dmat4& model);
struct TangentFrame {
  dvec3 normal, tangent, bitangent;
};
// gbuffer.vert: n through the normal matrix, t through the model matrix (it lies in
// the surface), b = cross(n, t) * w (w = -1 where the UVs are mirrored).
TangentFrame world_tangent_frame(const dmat4& model, dvec3 normal, dvec4 tangent);
// gbuffer.frag: any unit vector perpendicular to unit n.
dvec3 any_perpendicular(dvec3 n);
// gbuffer.frag mapped_normal: Gram-Schmidt on the (interpolated) frame, then the
// tangent-space normal from the texel, stored as (n + 1)/2, scaled in x and y.
dvec3 mapped_normal(const TangentFrame& frame, dvec3 texel, double normal_scale, const Guards& guards = {});

// --- Lab 5: bloom (solutions/05-postprocess) -------------------------------------------
// bright.frag: non-finite pixels dropped, clamped to KIT_HDR_MAX, kept when their
// luminance exceeds the threshold.
dvec3 bright_pass(dvec3 hdr, double threshold, const Guards& guards = {});
// blur.frag: one direction of the 9-tap Gaussian, taps at texel centres, clamped to the edge.
Image blur_pass(const Image& image, bool horizontal);
// bright_pass then settings.blur_passes blur passes, horizontal first.
Image bloom(const Image& hdr, const ShadingSettings& settings);
// composite.frag: tonemap(hdr + bloom) with the bloom on, tonemap(hdr) with it off.
Image composite(const Image& hdr, const Image& bloom, const ShadingSettings& settings);

// --- Analytic geometry, for reference samples without a rasteriser ------------------------
struct Ray {
  dvec3 origin, direction;  // direction is unit
};
// The camera ray through image point (x, y): pixel coordinates, top row first,
// pixel centres at +0.5, for a target of width x height.
Ray camera_ray(const FrameCamera& camera, int width, int height, double x, double y);
struct Hit {
  double t = 0.0;
  dvec3 position{0.0}, normal{0.0};
};
// Nearest front-facing hit with t > 0 (the G-buffer culls back faces).
std::optional<Hit> intersect_sphere(const Ray& ray, dvec3 center, double radius);
std::optional<Hit> intersect_plane(const Ray& ray, dvec3 point, dvec3 normal);
// The surface a hit shows with `material`'s factors (textures are not sampled) and
// the vertex colour there.
SurfaceSample surface_sample(const Hit& hit, const Material& material, dvec4 vertex_color = dvec4(1.0));

// --- Geometry pass (lab 1) --------------------------------------------------------
// Vertex::color as the GPU reads it (normalized unsigned short: c / 65535).
dvec4 vertex_color(const Vertex& vertex);
// glTF's base colour: baseColorFactor x base colour texel (linear) x COLOR_0, alpha
// included (the alpha modes read it); albedo.rgba of the G-buffer.
dvec4 base_color(const Material& material, dvec4 linear_texel, dvec4 vertex_color);

}  // namespace kit::reference
