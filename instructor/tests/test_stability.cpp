// The shading's failure cases, each with a witness: a naive variant of the
// solution (a copy of solutions/ with the guarded line swapped for the textbook
// one, rendered through the normal pipeline) or the naive formula evaluated by the
// CPU reference with that guard switched off, shown to really break on the test's
// scene, and the kit's method shown not to on the same scene.
//
// Scenes are the smallest that trigger each case, mostly built in code
// (tests/support/tiny_scenes.h): one floor, one light, one camera.
//
// How a failure shows in the HDR target: NaN or Inf, or pinned at the fp16
// ceiling. lighting.frag ends with min(radiance, KIT_HDR_MAX), which turns +Inf
// into KIT_HDR_MAX, and llvmpipe's min(NaN, x) returns x, so there a NaN lands on
// the ceiling too. broken_pixels() counts all of these; the CPU reference then
// shows what the shader computed before that clamp.
//
// Cases (numbered as in the issue): (1) grazing n.v and n.l, (2) roughness 0,
// (3) a light at distance 0, (4) spot umbra = penumbra, (6) normal mapping,
// (8) non-finite HDR through the bloom, (9) tone mapping of very bright pixels.
// Cases 5 and 7 are tested elsewhere. Where the GPU cannot show a failure (the
// exact zero of n.v at a silhouette, smoothstep(e, e, x) at x == e, which llvmpipe
// happens to resolve as a hard edge), the witness is the CPU reference with that
// guard off. Note for (1): on the kit's own grazing and sphere scenes, removing the
// n.v/n.l floors changes no pixel measurably, because the lighting pass skips
// n.l <= 0 and the min() form of G cancels n.v; they matter at exact zeros.
#include <glm/gtc/matrix_transform.hpp>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "cpu_reference.h"
#include "gbuffer_layout.h"
#include "kit_test.h"
#include "reference_frames.h"
#include "shader_variants.h"
#include "tiny_scenes.h"

namespace kit::test {
namespace {

namespace ref = kit::reference;
using ref::dvec3;

// ---------------------------------------------------------------------------
// The naive variants: each row is the kit's guarded line and what a textbook
// implementation writes instead.

// (1) The BRDF without its n.v, n.l and v.h floors and the guard on 4 (n.l)(n.v).
const std::vector<LineSwap> kBrdfWithoutAngleFloors = {
    {"02-lighting/brdf.glsl", "float n_dot_v = max(dot(n, v), KIT_MIN_N_DOT_V);", "float n_dot_v = dot(n, v);"},
    {"02-lighting/brdf.glsl", "float n_dot_l = max(dot(n, l), KIT_MIN_N_DOT_L);", "float n_dot_l = dot(n, l);"},
    {"02-lighting/brdf.glsl", "float v_dot_h = max(dot(v, h), KIT_MIN_V_DOT_H);", "float v_dot_h = dot(v, h);"},
    {"02-lighting/brdf.glsl", "max(4.0 * n_dot_l * n_dot_v, KIT_MIN_DENOMINATOR)", "(4.0 * n_dot_l * n_dot_v)"},
};
// (1) A lighting pass that clamps n.l at 0 instead of skipping the light, so the
// BRDF itself is evaluated at n.l = 0 (a common way to write the loop).
const LineSwap kLightingClampsNDotL = {"02-lighting/lighting.frag", "if (n_dot_l <= 0.0) continue;",
                                      "n_dot_l = max(n_dot_l, 0.0);"};
// (2) No roughness floor, and GGX's denominator unguarded: D = 0/0 at n.h = 1.
const std::vector<LineSwap> kBrdfWithoutRoughnessFloor = {
    {"02-lighting/brdf.glsl", "float roughness = max(perceptual_roughness, KIT_MIN_ROUGHNESS);",
     "float roughness = perceptual_roughness;"},
    {"02-lighting/brdf.glsl", "return alpha2 / max(KIT_PI * d * d, KIT_MIN_GGX_DENOMINATOR);",
     "return alpha2 / (KIT_PI * d * d);"},
};
// (3) r^2 unfloored wherever the kit floors it: the light direction, the inverse
// square, the spot direction.
const std::vector<LineSwap> kWithoutDistanceFloor = {
    {"02-lighting/lighting.frag",
     "l = to_light * inversesqrt(max(dot(to_light, to_light), KIT_MIN_DISTANCE_SQUARED));",
     "l = normalize(to_light);"},
    {"03-attenuation/attenuation.glsl", "float r2 = max(dot(to_light, to_light), KIT_MIN_DISTANCE_SQUARED);",
     "float r2 = dot(to_light, to_light);"},
    {"03-attenuation/attenuation.glsl",
     "from_light *= inversesqrt(max(dot(from_light, from_light), KIT_MIN_DISTANCE_SQUARED));",
     "from_light = normalize(from_light);"},
};
// (4) GLSL's smoothstep between the cone cosines (undefined when they are equal).
const LineSwap kSpotGlslSmoothstep = {
    "03-attenuation/attenuation.glsl",
    "float t = clamp((cos_angle - light.cos_outer) / max(light.cos_inner - light.cos_outer, KIT_MIN_CONE_COS_GAP), "
    "0.0, 1.0);\n    return t * t * (3.0 - 2.0 * t);",
    "return smoothstep(light.cos_outer, light.cos_inner, cos_angle);"};
// (4) The spot normalisation 1 - (cos_inner + cos_outer)/2 unfloored.
const LineSwap kSpotWithoutSolidAngleFloor = {
    "03-attenuation/attenuation.glsl",
    "float solid = max(1.0 - 0.5 * (light.cos_inner + light.cos_outer), KIT_MIN_SPOT_SOLID_ANGLE);",
    "float solid = 1.0 - 0.5 * (light.cos_inner + light.cos_outer);"};
// (6) The bitangent without the handedness sign.
const LineSwap kIgnoreHandedness = {"04-normalmap/gbuffer.vert", "v_world_bitangent = cross(n, t) * a_tangent.w;",
                                    "v_world_bitangent = cross(n, t);"};
// (6) The tangent frame normalised without looking at its length.
const std::vector<LineSwap> kTangentFrameUnguarded = {
    {"04-normalmap/gbuffer.frag",
     "t = t_len2 > KIT_MIN_TANGENT_LENGTH_SQUARED ? t * inversesqrt(t_len2) : any_perpendicular(n);",
     "t = normalize(t);"},
    {"04-normalmap/gbuffer.frag", "b = b_len2 > KIT_MIN_TANGENT_LENGTH_SQUARED ? b * inversesqrt(b_len2) : cross(n, t);",
     "b = normalize(b);"},
    {"04-normalmap/gbuffer.frag", "return len2 > KIT_MIN_TANGENT_LENGTH_SQUARED ? world * inversesqrt(len2) : n;",
     "return normalize(world);"},
};
// (6) Normals through the model matrix instead of its inverse transpose.
const LineSwap kNormalsThroughModelMatrix = {"04-normalmap/gbuffer.vert",
                                             "vec3 n = normalize(u_normal_matrix * a_normal);",
                                             "vec3 n = normalize(mat3(u_model) * a_normal);"};
// (8) Test injection, not a naive variant: the lighting pass writes a quiet NaN
// at one pixel and +Inf at another, after its own clamp. GL window coordinates
// (rows bottom-up).
constexpr int kNanPixelX = 40, kInfPixelX = 120, kInjectedPixelY = 60;
LineSwap inject_non_finite() {
  auto at = [](int x, const char* bits) {
    return "\n    if (ivec2(gl_FragCoord.xy) == ivec2(" + std::to_string(x) + ", " + std::to_string(kInjectedPixelY) +
           ")) out_color.rgb = vec3(intBitsToFloat(" + bits + "));";
  };
  const std::string line = "out_color = vec4(min(radiance, vec3(KIT_HDR_MAX)), 1.0);";
  return {"02-lighting/lighting.frag", line, line + at(kNanPixelX, "0x7fc00000") + at(kInfPixelX, "0x7f800000")};
}
// (8) The bright pass without its non-finite test.
const LineSwap kBrightPassKeepsNonFinite = {"05-postprocess/bright.frag",
                                            "if (any(isnan(c)) || any(isinf(c))) c = vec3(0.0);", ""};
// (9) Gamma without Reinhard: pow(c, 1/gamma) alone.
const LineSwap kGammaWithoutReinhard = {"03-attenuation/tonemap.glsl",
                                        "vec3 mapped = max(hdr, 0.0) / (max(hdr, 0.0) + 1.0);",
                                        "vec3 mapped = max(hdr, 0.0);"};

// ---------------------------------------------------------------------------

// Largest angle, in degrees, between a G-buffer normal and the CPU-expected one
// that counts as agreeing: fp16 storage, even truncating (llvmpipe), moves a unit
// vector by under 0.1 degree; the 8-bit normal-map texel decodes exactly on both sides.
constexpr double kNormalAgreementDegrees = 0.25;

double max3(dvec3 v) { return std::max(v.x, std::max(v.y, v.z)); }

// An HDR value a shading failure left: non-finite, pinned at the fp16 ceiling, or negative.
bool broken(dvec3 c) {
  return !finite(c) || glm::any(glm::greaterThanEqual(c, dvec3(ref::KIT_HDR_MAX))) ||
         glm::any(glm::lessThan(c, dvec3(0.0)));
}

size_t broken_pixels(const Image& hdr) {
  size_t count = 0;
  for (int y = 0; y < hdr.height; ++y)
    for (int x = 0; x < hdr.width; ++x) count += broken(pixel_rgb(hdr, x, y));
  return count;
}

Frame render_kit(const std::string& stage, const Scene& s, const FrameCamera& camera,
                 const RenderSettings& settings = small_settings()) {
  return render_frame(*make_renderer(stage, s, settings), camera);
}

// Renders `stage` with a copy of solutions/ named `name` whose lines `swaps` replaces.
Frame render_variant(const std::string& stage, const Scene& s, const FrameCamera& camera, const std::string& name,
                     const std::vector<LineSwap>& swaps, const RenderSettings& settings = small_settings()) {
  auto renderer = make_renderer(stage, s, settings, full_root_library(find_stage(stage), variant_root(name, swaps)));
  return render_frame(*renderer, camera);
}

// The kit's frame agrees with the CPU reference on every covered pixel.
void expect_matches_reference(const Frame& frame, const Scene& s, const std::string& label,
                              const RenderSettings& settings = small_settings()) {
  const Agreement a = compare_with_reference(frame, ref::frame_lights(s, settings),
                                             ref::shading_settings(settings, frame.stage), covered_pixels(frame));
  std::printf("[ stability ] %s, kit against the CPU reference: %s\n", label.c_str(), describe(a).c_str());
  EXPECT_EQ(a.failures, 0u) << label << ": " << describe(a);
}

void report(const std::string& label, size_t count, size_t of) {
  std::printf("[ stability ] %s: %zu of %zu pixels broken\n", label.c_str(), count, of);
}

// ---------------------------------------------------------------------------
// (1) Grazing light and view.

// A point light lying in the floor's plane: every floor position has y = 0 exactly
// (interpolated from vertices at y = 0), so n.l = 0 exactly everywhere. With the
// light skipped (the kit's lighting pass) nothing is evaluated there; a lighting
// pass that clamps n.l to 0 evaluates the BRDF at n.l = 0, where G = 0 and the
// specular denominator 4 (n.l)(n.v) = 0: 0/0 without the floors.
TEST(Stability, GrazingLightInTheSurfacePlane) {
  const Scene s = floor_scene(plain_material(0.3f), {point_light({0.0f, 0.0f, -1.0f}, 30.0f)});
  const FrameCamera camera = look_at_camera({0, 1, 4}, {0, 0, -1}, 0.8f, small_settings());

  const Frame kit = render_kit("attenuation", s, camera);
  const PixelList floor = covered_pixels(kit);
  size_t in_plane = 0;
  for (const auto& [x, y] : floor) in_plane += kit.gbuffer.position.at(x, y, 1) == 0.0f;
  ASSERT_EQ(in_plane, floor.size()) << "the premise: every floor position lies exactly in the light's plane";

  const Frame clamped = render_variant("attenuation", s, camera, "stability_grazing_clamp", {kLightingClampsNDotL});
  std::vector<LineSwap> naive = kBrdfWithoutAngleFloors;
  naive.push_back(kLightingClampsNDotL);
  const Frame witness = render_variant("attenuation", s, camera, "stability_grazing_naive", naive);
  report("light in the plane, kit", broken_pixels(kit.hdr), floor.size());
  report("light in the plane, n.l clamped, kit BRDF", broken_pixels(clamped.hdr), floor.size());
  report("light in the plane, n.l clamped, BRDF without floors", broken_pixels(witness.hdr), floor.size());
  EXPECT_EQ(broken_pixels(witness.hdr), floor.size()) << "witness: 0/0 on every floor pixel";
  EXPECT_EQ(broken_pixels(kit.hdr), 0u);
  EXPECT_EQ(broken_pixels(clamped.hdr), 0u) << "the BRDF's floors alone must keep n.l = 0 finite";

  // The CPU reference at one of these pixels: the naive BRDF is 0/0, the kit's finite.
  const auto [x, y] = floor[floor.size() / 2];
  const ref::SurfaceSample sample = ref::gbuffer_sample(kit.gbuffer, x, y);
  const dvec3 v = glm::normalize(dvec3(camera.position) - sample.position);
  const dvec3 l = glm::normalize(dvec3(s.lights[0].position) - sample.position);
  ASSERT_EQ(glm::dot(glm::normalize(sample.normal), l), 0.0);
  EXPECT_FALSE(finite(ref::cook_torrance(sample.normal, v, l, sample.albedo, 0.0, 0.3, ref::Guards::none())));
  EXPECT_TRUE(finite(ref::cook_torrance(sample.normal, v, l, sample.albedo, 0.0, 0.3)));
}

// A camera ray that just touches the sphere meets it where n.v = 0 exactly: the
// silhouette. The textbook BRDF is 0/0 there; the kit's stays finite. On the GPU,
// interpolated normals at a tessellated silhouette give n.v small but not exactly
// 0, where the kit's frames (the grazing scene's far plane and a close-up of the
// sphere's outline) stay finite, non-negative and match the CPU reference.
TEST(Stability, GrazingViewAtTheSilhouette) {
  const Scene& sphere = scene("sphere");
  const ref::Ray tangent_ray{{1.0, 0.0, 4.0}, {0.0, 0.0, -1.0}};
  const std::optional<ref::Hit> hit = ref::intersect_sphere(tangent_ray, dvec3(0.0), 1.0);
  ASSERT_TRUE(hit.has_value());
  ASSERT_EQ(glm::dot(hit->normal, -tangent_ray.direction), 0.0) << "the premise: n.v = 0 exactly";
  const ref::SurfaceSample surface = ref::surface_sample(*hit, sphere.materials[0]);
  ref::ShadingSettings naive;
  naive.guards = ref::Guards::none();
  EXPECT_FALSE(finite(ref::shade(surface, tangent_ray.origin, sphere.lights, naive))) << "witness: 0/0 at n.v = 0";
  EXPECT_TRUE(finite(ref::shade(surface, tangent_ray.origin, sphere.lights, ref::ShadingSettings{})));

  const Frame outline = render_kit("attenuation", sphere, sphere_silhouette_camera(sphere, small_settings()));
  const Scene& plane = scene("grazing");
  const Frame horizon = render_kit("attenuation", plane, scene_frame_camera(plane, small_settings()));
  for (const Frame* f : {&outline, &horizon}) {
    EXPECT_GT(grazing_pixels(*f, 0.05).size(), 100u);
    EXPECT_EQ(broken_pixels(f->hdr), 0u);
  }
  expect_matches_reference(outline, sphere, "sphere silhouette close-up");
  expect_matches_reference(horizon, plane, "grazing plane");
}

// ---------------------------------------------------------------------------
// (2) Roughness 0: GGX's D at n.h = 1 is alpha^2 / (pi ((alpha^2 - 1) + 1)^2) = 0/0.
// A mirror floor seen straight down through a 0.001 rad field of view with the
// light above the camera: n.h rounds to exactly 1 in float over most pixels.
TEST(Stability, RoughnessZero) {
  const Scene s = floor_scene(plain_material(0.0f), {point_light({0.0f, 2.0f, 0.0f}, 30.0f)});
  const FrameCamera camera = look_at_camera({0, 1, 0}, {0, 0, 0}, 0.001f, small_settings());
  const Frame kit = render_kit("attenuation", s, camera);
  const Frame witness = render_variant("attenuation", s, camera, "stability_roughness_zero", kBrdfWithoutRoughnessFloor);
  const size_t covered = covered_pixels(kit).size();
  report("roughness 0, kit", broken_pixels(kit.hdr), covered);
  report("roughness 0, no roughness floor", broken_pixels(witness.hdr), covered);
  EXPECT_GT(broken_pixels(witness.hdr), covered / 4) << "witness: D = 0/0 where n.h = 1";
  EXPECT_EQ(broken_pixels(kit.hdr), 0u);
  expect_matches_reference(kit, s, "roughness 0");

  const double alpha_min = ref::KIT_MIN_ROUGHNESS * ref::KIT_MIN_ROUGHNESS;
  EXPECT_TRUE(std::isnan(ref::distribution_ggx(1.0, 0.0, ref::Guards::none())));
  // The floored peak is GGX's own 1/(pi alpha^2), not capped by a denominator guard
  // (d = (alpha^2 - 1) + 1 cancels to about 1e-11 relative in double).
  const double peak = 1.0 / (ref::KIT_PI * alpha_min * alpha_min);
  EXPECT_NEAR(ref::distribution_ggx(1.0, alpha_min), peak, 1e-9 * peak);
}

// ---------------------------------------------------------------------------
// (3) A light at distance 0 from a surface.

// Exactly on a surface point: the light is placed at the fp16 position one pixel
// of the G-buffer holds, so r = 0 there: l = 0 * inf and flux / 0 without the floor.
TEST(Stability, LightExactlyOnTheSurface) {
  Scene s = floor_scene(plain_material(0.5f), {point_light({0.0f, 1.0f, 0.0f}, 1.0f)});
  const FrameCamera camera = look_at_camera({0, 2, 2}, {0, 0, 0}, 0.8f, small_settings());
  constexpr int kX = kSmallWidth / 2, kY = kSmallHeight / 2;
  const Frame first = render_kit("attenuation", s, camera);
  s.lights[0].position = glm::vec3(ref::gbuffer_sample(first.gbuffer, kX, kY).position);

  const Frame kit = render_kit("attenuation", s, camera);
  const Frame witness = render_variant("attenuation", s, camera, "stability_light_on_surface", kWithoutDistanceFloor);
  ASSERT_EQ(ref::gbuffer_sample(kit.gbuffer, kX, kY).position, dvec3(s.lights[0].position)) << "the premise: r = 0";
  const size_t covered = covered_pixels(kit).size();
  report("light on a surface point, kit", broken_pixels(kit.hdr), covered);
  report("light on a surface point, no r^2 floor", broken_pixels(witness.hdr), covered);
  EXPECT_TRUE(broken(pixel_rgb(witness.hdr, kX, kY))) << "witness: the pixel under the light";
  EXPECT_EQ(broken_pixels(kit.hdr), 0u);
  expect_matches_reference(kit, s, "light on a surface point");

  ref::ShadingSettings naive;
  naive.guards = ref::Guards::none();
  const ref::ShadingLight light = ref::uploaded_light(s.lights[0]);
  EXPECT_FALSE(finite(ref::light_radiance(light, light.position, naive))) << "flux / (4 pi 0)";
  EXPECT_TRUE(finite(ref::light_radiance(light, light.position, ref::ShadingSettings{})));
}

// One millimetre above the floor, seen close up: without the floor the inverse
// square exceeds what fp16 holds (stored as +Inf but for the lighting pass's clamp);
// with r^2 floored at 1 cm^2 the peak stays bounded.
TEST(Stability, LightAMillimetreAboveTheSurface) {
  const Scene s = floor_scene(plain_material(0.5f), {point_light({0.0f, 0.001f, 0.0f}, 1.0f)});
  const FrameCamera camera = look_at_camera({0, 0.5f, 0.5f}, {0, 0, 0}, 0.05f, small_settings());
  const Frame kit = render_kit("attenuation", s, camera);
  const Frame witness = render_variant("attenuation", s, camera, "stability_light_near_surface", kWithoutDistanceFloor);
  const PixelList floor = covered_pixels(kit);
  report("light 1 mm above, kit", broken_pixels(kit.hdr), floor.size());
  report("light 1 mm above, no r^2 floor", broken_pixels(witness.hdr), floor.size());
  EXPECT_GT(broken_pixels(witness.hdr), 10u) << "witness: radiance past the fp16 range";
  EXPECT_EQ(broken_pixels(kit.hdr), 0u);
  expect_matches_reference(kit, s, "light 1 mm above");

  // Where the witness broke, the naive formula (CPU) is past the largest half.
  ref::ShadingSettings naive = ref::shading_settings(small_settings(), 3);
  naive.guards = ref::Guards::none();
  for (const auto& [x, y] : floor) {
    if (pixel_rgb(witness.hdr, x, y).x < ref::KIT_HDR_MAX) continue;
    const dvec3 c = ref::shade(ref::gbuffer_sample(witness.gbuffer, x, y), dvec3(camera.position), s.lights, naive);
    EXPECT_GT(c.x, ref::KIT_HDR_MAX) << "pixel (" << x << ", " << y << ")";
  }
}

// ---------------------------------------------------------------------------
// (4) Spot lights with umbra = penumbra.

Light spot_light(float cone) {
  Light l;
  l.type = KIT_LIGHT_SPOT;
  l.position = {0.0f, 2.0f, 0.0f};
  l.direction = {0.0f, -1.0f, 0.0f};
  l.intensity = 10.0f;
  l.inner_cone = cone;
  l.outer_cone = cone;
  return l;
}

// GLSL leaves smoothstep(e, e, x) undefined; its formula divides by e - e. The CPU
// evaluation of it at a point exactly on the cone (cos_angle == e) is 0/0; the
// kit's floored gap gives the hard edge. On the GPU the kit's hard edge matches the
// CPU reference (llvmpipe happens to give a hard edge for the naive one too, so the
// GPU variant is only reported).
TEST(Stability, SpotWithUmbraEqualToPenumbra) {
  ref::ShadingLight light = ref::uploaded_light(spot_light(0.3f));
  const dvec3 p = light.position + dvec3(3.0, -4.0, 0.0);
  dvec3 from_light = p - light.position;
  from_light *= 1.0 / std::sqrt(glm::dot(from_light, from_light));
  light.cos_inner = light.cos_outer = glm::dot(from_light, light.direction);  // p exactly on the cone
  EXPECT_TRUE(std::isnan(ref::spot_cone_factor(light, p, ref::Guards::none()))) << "witness: 0/0 on the cone";
  EXPECT_EQ(ref::spot_cone_factor(light, p), 0.0);

  const Scene s = floor_scene(plain_material(0.5f), {spot_light(0.3f)});
  const FrameCamera camera = look_at_camera({0, 3, 3}, {0, 0, 0}, 0.8f, small_settings());
  const Frame kit = render_kit("attenuation", s, camera);
  const Frame glsl = render_variant("attenuation", s, camera, "stability_spot_smoothstep", {kSpotGlslSmoothstep});
  report("spot umbra = penumbra, kit", broken_pixels(kit.hdr), covered_pixels(kit).size());
  report("spot umbra = penumbra, GLSL smoothstep (undefined; reported only)", broken_pixels(glsl.hdr),
         covered_pixels(glsl).size());
  EXPECT_EQ(broken_pixels(kit.hdr), 0u);
  expect_matches_reference(kit, s, "spot umbra = penumbra");
}

// A cone of 1e-4 rad: both cosines round to 1 in float, so the uploaded flux and the
// normalisation 1 - (cos_i + cos_o)/2 are both 0, and flux / (2 pi r^2 * 0) = 0/0
// lights every pixel with NaN. Floored, the spot contributes 0 (no pixel centre lies
// in a cone 0.4 mm wide at 2 m).
TEST(Stability, SpotNormalisationWithBothCosinesNearOne) {
  const ref::ShadingLight uploaded = ref::uploaded_light(spot_light(1e-4f));
  ASSERT_EQ(uploaded.cos_inner, 1.0);
  ASSERT_EQ(uploaded.cos_outer, 1.0);
  ASSERT_EQ(uploaded.flux, 0.0);

  const Scene s = floor_scene(plain_material(0.5f), {spot_light(1e-4f)});
  const FrameCamera camera = look_at_camera({0, 3, 3}, {0, 0, 0}, 0.8f, small_settings());
  const Frame kit = render_kit("attenuation", s, camera);
  const Frame witness = render_variant("attenuation", s, camera, "stability_spot_narrow", {kSpotWithoutSolidAngleFloor});
  const size_t covered = covered_pixels(kit).size();
  report("spot cone 1e-4 rad, kit", broken_pixels(kit.hdr), covered);
  report("spot cone 1e-4 rad, no solid-angle floor", broken_pixels(witness.hdr), covered);
  EXPECT_EQ(broken_pixels(witness.hdr), covered) << "witness: 0/0 on every lit pixel";
  EXPECT_EQ(broken_pixels(kit.hdr), 0u);
  expect_matches_reference(kit, s, "spot cone 1e-4 rad");

  ref::ShadingSettings naive;
  naive.guards = ref::Guards::none();
  const dvec3 below = uploaded.position + dvec3(0.0, -2.0, 0.0);
  EXPECT_FALSE(finite(ref::light_radiance(uploaded, below, naive)));
  EXPECT_TRUE(finite(ref::light_radiance(uploaded, below, ref::ShadingSettings{})));
}

// ---------------------------------------------------------------------------
// (6) Normal mapping.

// A 1x1 normal map holding one tangent-space normal, tilted towards the image's
// up direction (+Y, OpenGL convention as glTF requires).
constexpr unsigned char kTiltedTexel[4] = {128, 191, 238, 255};  // (n + 1)/2 of ~(0, 0.5, 0.87)
dvec3 tilted_texel() { return dvec3(kTiltedTexel[0], kTiltedTexel[1], kTiltedTexel[2]) / 255.0; }

Material normal_mapped_material() {
  Material m = plain_material(0.5f);
  m.texture(KIT_UNIT_NORMAL_MAP).image = 0;
  return m;
}

// Quads facing the camera (+Z) under the tilted normal map, at x = -1.1 and +1.1.
Scene normal_map_scene(std::vector<Primitive> quads) {
  std::vector<DrawItem> draws;
  for (size_t i = 0; i < quads.size(); ++i) {
    quads[i].material = 0;
    const float x = quads.size() == 1 ? 0.0f : (i == 0 ? -1.1f : 1.1f);
    draws.push_back({static_cast<int>(i), glm::translate(glm::mat4(1.0f), {x, 0.0f, 0.0f})});
  }
  Scene s = tiny_scene(std::move(quads), {normal_mapped_material()}, draws, {point_light({0.0f, 0.0f, 2.5f}, 40.0f)});
  ImageRgba8 map;
  map.width = map.height = 1;
  map.pixels.assign(kTiltedTexel, kTiltedTexel + 4);
  s.images.push_back({"tilted normal texel", map.width, map.height, {}, map});
  return s;
}

FrameCamera front_camera() { return look_at_camera({0, 0, 6}, {0, 0, 0}, 0.9f, small_settings()); }

// The expected world normal on a quad facing +Z: the texel through the frame whose
// tangent points along increasing u (right, or left when mirrored) and whose
// bitangent points to the image's top (+Y); derived from the quad, not the mesh.
dvec3 expected_quad_normal(bool mirrored) {
  const ref::TangentFrame frame{{0, 0, 1}, {mirrored ? -1.0 : 1.0, 0, 0}, {0, 1, 0}};
  return ref::mapped_normal(frame, tilted_texel(), 1.0);
}

// Angles between the G-buffer normals and `expected(pixel)` over the covered pixels.
template <typename Expected>
std::vector<double> normal_errors(const Frame& f, Expected expected) {
  std::vector<double> out;
  for (const auto& [x, y] : covered_pixels(f)) {
    const dvec3 n = pixel_rgb(f.gbuffer.normal, x, y);
    out.push_back(finite(n) ? angle_degrees(n, expected(x, y)) : INFINITY);
  }
  return out;
}

double max_of(const std::vector<double>& v) {
  double m = 0.0;
  for (double x : v) m = std::max(m, x);
  return m;
}

// Mirrored UVs (TANGENT.w = -1): ignoring w flips the bitangent, so the tilt
// towards the image's top comes out pointing down on the mirrored quad.
TEST(Stability, NormalMapMirroredUvs) {
  const Scene s = normal_map_scene({quad_primitive({1, 0, 0}, {0, 1, 0}, {2, 2}, false),
                                    quad_primitive({1, 0, 0}, {0, 1, 0}, {2, 2}, true)});
  ASSERT_EQ(s.primitives[1].vertices[0].tangent.w, -1.0f) << "the premise: the mirrored quad has w = -1";
  const Frame kit = render_kit("normalmap", s, front_camera());
  const Frame witness = render_variant("normalmap", s, front_camera(), "stability_handedness", {kIgnoreHandedness});
  auto expected = [&](const Frame& f) {
    return [&f](int x, int y) { return expected_quad_normal(f.gbuffer.position.at(x, y, 0) > 0.0f); };
  };
  // The expected normal leans to +Y on both quads; count pixels leaning the other way.
  auto wrong_sign = [](const Frame& f) {
    size_t n = 0;
    for (const auto& [x, y] : covered_pixels(f)) n += f.gbuffer.normal.at(x, y, 1) < 0.0f;
    return n;
  };
  const double kit_error = max_of(normal_errors(kit, expected(kit)));
  const double witness_error = max_of(normal_errors(witness, expected(witness)));
  const size_t mirrored_pixels = [&] {
    size_t n = 0;
    for (const auto& [x, y] : covered_pixels(kit)) n += kit.gbuffer.position.at(x, y, 0) > 0.0f;
    return n;
  }();
  std::printf("[ stability ] mirrored UVs: kit max error %.3f deg, %zu wrong-sign pixels; w ignored: max error %.1f deg, "
              "%zu wrong-sign pixels of %zu on the mirrored quad\n",
              kit_error, wrong_sign(kit), witness_error, wrong_sign(witness), mirrored_pixels);
  EXPECT_LT(kit_error, kNormalAgreementDegrees);
  EXPECT_EQ(wrong_sign(kit), 0u);
  EXPECT_EQ(wrong_sign(witness), mirrored_pixels) << "witness: every mirrored pixel leans the wrong way";
  EXPECT_GT(witness_error, 45.0);
}

// Degenerate UVs: a triangle with zero UV area has no tangent. The loader's
// generate_tangents still gives a unit tangent perpendicular to n, where the
// textbook per-triangle formula divides by the zero UV determinant. A file may also
// carry zero tangents for such triangles: the kit's frame falls back to any
// perpendicular and stays finite, an unguarded normalize() gives NaN normals.
TEST(Stability, NormalMapDegenerateTangents) {
  Primitive flat_uv = quad_primitive({1, 0, 0}, {0, 1, 0}, {2, 2});
  for (Vertex& v : flat_uv.vertices) v.texcoord = glm::vec2(0.5f);
  const Vertex &a = flat_uv.vertices[0], &b = flat_uv.vertices[1], &c = flat_uv.vertices[2];
  const glm::vec2 d1 = b.texcoord - a.texcoord, d2 = c.texcoord - a.texcoord;
  const float det = d1.x * d2.y - d2.x * d1.y;
  const glm::vec3 textbook = ((b.position - a.position) * d2.y - (c.position - a.position) * d1.y) / det;
  EXPECT_FALSE(std::isfinite(textbook.x)) << "witness: the textbook tangent of a zero-area UV triangle";
  generate_tangents(flat_uv.vertices, flat_uv.indices);
  for (const Vertex& v : flat_uv.vertices) {
    const glm::vec3 t(v.tangent);
    EXPECT_TRUE(std::isfinite(t.x) && std::isfinite(t.y) && std::isfinite(t.z));
    EXPECT_NEAR(glm::length(t), 1.0f, 1e-6f);
    EXPECT_NEAR(glm::dot(t, v.normal), 0.0f, 1e-6f);
  }

  Primitive zero_tangents = quad_primitive({1, 0, 0}, {0, 1, 0}, {2, 2});
  for (Vertex& v : zero_tangents.vertices) v.tangent = glm::vec4(0.0f, 0.0f, 0.0f, 1.0f);
  const Scene s = normal_map_scene({zero_tangents});
  const Frame kit = render_kit("normalmap", s, front_camera());
  const Frame witness = render_variant("normalmap", s, front_camera(), "stability_zero_tangent", kTangentFrameUnguarded);
  // The CPU mirror of both shader stages on the same vertex data.
  const ref::TangentFrame frame = ref::world_tangent_frame(glm::dmat4(1.0), dvec3(0, 0, 1), glm::dvec4(0, 0, 0, 1));
  const dvec3 expected = ref::mapped_normal(frame, tilted_texel(), 1.0);
  const size_t covered = covered_pixels(kit).size();
  const size_t nan_normals = count_non_finite(witness.gbuffer.normal);
  const double kit_error = max_of(normal_errors(kit, [&](int, int) { return expected; }));
  std::printf("[ stability ] zero tangents: kit max error %.3f deg, %zu non-finite normals; unguarded: %zu of %zu "
              "non-finite\n",
              kit_error, count_non_finite(kit.gbuffer.normal), nan_normals, covered);
  EXPECT_EQ(nan_normals, covered) << "witness: NaN normals from normalize(0)";
  EXPECT_EQ(count_non_finite(kit.gbuffer.normal), 0u);
  EXPECT_LT(kit_error, kNormalAgreementDegrees);
}

// A mesh without TANGENT: the loader generates tangents (with w from the UV layout).
// Left at zero, the kit's shader stays finite but builds an arbitrary frame, and the
// mapped normal points the wrong way; generated, it matches the expected direction.
TEST(Stability, NormalMapMeshWithoutTangents) {
  const Scene& file = scene("normalmap");
  bool found = false;
  for (const Primitive& p : file.primitives) {
    if (p.name.find("sphere_no_tangents") == std::string::npos) continue;
    found = true;
    EXPECT_TRUE(p.tangents_generated);
    for (const Vertex& v : p.vertices) {
      EXPECT_NEAR(glm::length(glm::vec3(v.tangent)), 1.0f, 1e-5f);
      EXPECT_NEAR(glm::dot(glm::vec3(v.tangent), glm::normalize(v.normal)), 0.0f, 1e-5f);
      EXPECT_EQ(std::fabs(v.tangent.w), 1.0f);
    }
  }
  EXPECT_TRUE(found) << "the normalmap scene's sphere without TANGENT";

  const Primitive generated = quad_primitive({1, 0, 0}, {0, 1, 0}, {2, 2}, true);
  Primitive missing = generated;
  for (Vertex& v : missing.vertices) v.tangent = glm::vec4(0.0f);  // what a loader that skips generation holds
  const Scene with = normal_map_scene({generated});
  const Scene without = normal_map_scene({missing});
  const Frame kit = render_kit("normalmap", with, front_camera());
  const Frame witness = render_kit("normalmap", without, front_camera());
  const dvec3 expected = expected_quad_normal(true);
  const double kit_error = max_of(normal_errors(kit, [&](int, int) { return expected; }));
  const double witness_error = max_of(normal_errors(witness, [&](int, int) { return expected; }));
  std::printf("[ stability ] mesh without tangents: generated %.3f deg, left at zero %.1f deg from expected\n", kit_error,
              witness_error);
  EXPECT_LT(kit_error, kNormalAgreementDegrees);
  EXPECT_GT(witness_error, 20.0) << "witness: an arbitrary frame turns the mapped normal";
  EXPECT_EQ(count_non_finite(witness.gbuffer.normal), 0u);
}

// Non-uniform scale (2, 0.5, 1) over a quad tilted 30 degrees: the model matrix
// shears its normal off the surface; the normal matrix (inverse transpose) keeps it
// perpendicular. Expected: the cross product of the transformed edges, in double.
TEST(Stability, NormalMatrixUnderNonUniformScale) {
  Primitive quad = quad_primitive({1, 0, 0}, {0, 1, 0}, {2, 1});
  quad.material = 0;
  const glm::mat4 world = glm::scale(glm::mat4(1.0f), {2.0f, 0.5f, 1.0f}) *
                          glm::rotate(glm::mat4(1.0f), glm::radians(-30.0f), glm::vec3(1, 0, 0));
  const Scene s = tiny_scene({quad}, {plain_material(0.5f)}, {{0, world}}, {point_light({0, 0, 2.5f}, 40.0f)});
  const glm::dmat4 w(world);
  auto at = [&](int i) { return dvec3(w * glm::dvec4(glm::dvec3(s.primitives[0].vertices[i].position), 1.0)); };
  const dvec3 expected = glm::normalize(glm::cross(at(1) - at(0), at(2) - at(0)));
  const dvec3 through_model = glm::normalize(glm::dmat3(w) * dvec3(0, 0, 1));
  const dvec3 through_normal_matrix = glm::normalize(ref::normal_matrix(w) * dvec3(0, 0, 1));
  ASSERT_LT(angle_degrees(through_normal_matrix, expected), 1e-9);

  const FrameCamera camera = look_at_camera({0, 0.5f, 4}, {0, 0, 0}, 0.6f, small_settings());
  const Frame kit = render_kit("normalmap", s, camera);
  const Frame witness = render_variant("normalmap", s, camera, "stability_model_matrix_normals",
                                       {kNormalsThroughModelMatrix});
  const double kit_error = max_of(normal_errors(kit, [&](int, int) { return expected; }));
  const std::vector<double> witness_errors = normal_errors(witness, [&](int, int) { return expected; });
  std::printf("[ stability ] non-uniform scale: normal matrix %.3f deg, model matrix %.2f deg from expected "
              "(the CPU predicts %.2f deg)\n",
              kit_error, max_of(witness_errors), angle_degrees(through_model, expected));
  EXPECT_GT(covered_pixels(kit).size(), 1000u);
  EXPECT_LT(kit_error, kNormalAgreementDegrees);
  for (double e : witness_errors) EXPECT_NEAR(e, angle_degrees(through_model, expected), kNormalAgreementDegrees);
  EXPECT_GT(angle_degrees(through_model, expected), 10.0) << "witness: a measurable shear";
}

// ---------------------------------------------------------------------------
// (8) A NaN and an +Inf pixel in the HDR target (injected by a lighting-pass copy)
// must not spread through the bloom. Damage: pixels of the final image that differ
// from the same frame without the injection by more than one 8-bit step. The CPU
// mirror of the bloom shows the spread as non-finite pixels.
TEST(Stability, BloomContainsNonFinitePixels) {
  const Scene s = floor_scene(plain_material(0.5f), {point_light({0.0f, 2.0f, 0.0f}, 8.0f)});
  const FrameCamera camera = look_at_camera({0, 3, 3}, {0, 0, 0}, 0.8f, small_settings());
  const Frame clean = render_kit("postprocess", s, camera);
  const Frame kit = render_variant("postprocess", s, camera, "stability_bloom_kit", {inject_non_finite()});
  const Frame witness = render_variant("postprocess", s, camera, "stability_bloom_naive",
                                       {inject_non_finite(), kBrightPassKeepsNonFinite});
  ASSERT_EQ(count_non_finite(kit.hdr), 2u) << "the premise: two non-finite HDR pixels";
  auto damaged = [&](const Frame& f) {
    PixelList out;
    for (int y = 0; y < f.final.height; ++y)
      for (int x = 0; x < f.final.width; ++x)
        // NaN-safe: a NaN difference counts as damage.
        if (!(max3(glm::abs(stored_ldr(f.final, x, y) - stored_ldr(clean.final, x, y))) <= kLdrTolerance))
          out.emplace_back(x, y);
    return out;
  };
  auto damage = [&](const Frame& f) { return damaged(f).size(); };
  const ref::ShadingSettings settings = ref::shading_settings(small_settings(), 5);
  ref::ShadingSettings naive = settings;
  naive.guards = ref::Guards::none();
  const size_t cpu_kit = count_non_finite(ref::bloom(kit.hdr, settings));
  const size_t cpu_naive = count_non_finite(ref::bloom(kit.hdr, naive));
  std::printf("[ stability ] bloom over a NaN and an Inf pixel: damaged pixels kit %zu, naive bright pass %zu; "
              "CPU bloom non-finite pixels kit %zu, unguarded %zu\n",
              damage(kit), damage(witness), cpu_kit, cpu_naive);
  // The composite samples the HDR target bilinearly: where its interpolated uv lands a
  // hair off a texel centre, the neighbour's zero weight times NaN is still NaN. So the
  // kit's damage stays within one pixel of each injected one.
  const glm::ivec2 injected[2] = {{kNanPixelX, kSmallHeight - 1 - kInjectedPixelY}, {kInfPixelX, kSmallHeight - 1 - kInjectedPixelY}};
  for (const auto& [x, y] : damaged(kit)) {
    bool next_to_injected = false;
    for (const glm::ivec2& p : injected) next_to_injected |= std::abs(x - p.x) <= 1 && std::abs(y - p.y) <= 1;
    EXPECT_TRUE(next_to_injected) << "kit damage at (" << x << ", " << y << ")";
  }
  EXPECT_GT(damage(witness), 100u) << "witness: spread over the blur footprint";
  EXPECT_EQ(cpu_kit, 0u);
  // The +Inf pixel's footprint: 3 passes of 4 taps each way, 25 x 25. (Unguarded, the
  // NaN pixel's luminance fails `> threshold` and happens to be dropped; on the GPU,
  // llvmpipe's min(NaN, KIT_HDR_MAX) turns it into a bright pixel that spreads too.)
  EXPECT_GE(cpu_naive, 25u * 25u) << "witness: the Inf spread over the blur footprint in exact arithmetic";
}

// ---------------------------------------------------------------------------
// (9) Reinhard then gamma keeps every HDR value, up to the fp16 ceiling, in [0, 1)
// for gamma 0.5, 1.0 and 2.5; gamma alone sends everything above 1 past 1, where the
// 8-bit target clips it flat.
TEST(Stability, ToneMappingStaysBelowOne) {
  // 5e4 cd 20 cm above the floor, the floor seen out to 10 m: the HDR spans from
  // below 1 far away to pinned at KIT_HDR_MAX under the light.
  const Scene s = floor_scene(plain_material(0.5f), {point_light({0.0f, 0.2f, 0.0f}, 5e4f)});
  const FrameCamera camera = look_at_camera({0, 2, 8}, {0, 0, -4}, 1.2f, small_settings());
  auto kit = make_renderer("attenuation", s, small_settings());
  auto naive = make_renderer("attenuation", s, small_settings(),
                             full_root_library(find_stage("attenuation"),
                                               variant_root("stability_gamma_only", {kGammaWithoutReinhard})));
  for (float gamma : {0.5f, 1.0f, 2.5f}) {
    kit->settings().gamma = naive->settings().gamma = gamma;
    const Frame k = render_frame(*kit, camera);
    const Frame n = render_frame(*naive, camera);
    size_t above_one = 0, kit_clipped = 0, naive_clipped = 0, pinned = 0;
    double kit_max = 0.0, naive_max = 0.0, ldr_error = 0.0;
    for (const auto& [x, y] : covered_pixels(k)) {
      const dvec3 hdr = pixel_rgb(k.hdr, x, y);
      pinned += hdr.x >= ref::KIT_HDR_MAX;
      const dvec3 mapped = ref::tonemap(hdr, gamma);
      const dvec3 gamma_only = glm::pow(glm::max(hdr, 0.0), dvec3(1.0 / gamma));
      kit_max = std::max(kit_max, max3(mapped));
      naive_max = std::max(naive_max, max3(gamma_only));
      above_one += max3(gamma_only) > 1.0;
      ldr_error = std::max(ldr_error, max3(glm::abs(stored_ldr(k.final, x, y) - mapped)));
      kit_clipped += k.final.at(x, y, 0) == 1.0f;
      naive_clipped += n.final.at(x, y, 0) == 1.0f;
    }
    std::printf("[ stability ] gamma %.1f: %zu pixels at the fp16 ceiling; Reinhard max %.7f, displayed within "
                "%.2f/255, %zu pixels at 255; gamma alone max %.4g, %zu pixels above 1, %zu at 255\n",
                gamma, pinned, kit_max, ldr_error * 255.0, kit_clipped, naive_max, above_one, naive_clipped);
    EXPECT_GT(pinned, 0u) << "the premise: very bright pixels";
    EXPECT_LT(kit_max, 1.0);
    EXPECT_LE(ldr_error, kLdrTolerance);
    EXPECT_GT(naive_max, 1.0) << "witness: values past 1";
    EXPECT_GE(naive_clipped, above_one) << "witness: all of them clip to 255";
    EXPECT_GT(naive_clipped, 2 * kit_clipped);
  }
  for (double gamma : {0.5, 1.0, 2.5}) EXPECT_LT(max3(ref::tonemap(dvec3(ref::KIT_HDR_MAX), gamma)), 1.0);
}

}  // namespace
}  // namespace kit::test
