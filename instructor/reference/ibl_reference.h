#pragma once
// CPU reference for lab 6, image-based lighting, evaluated in double precision.
//
// The lab lights a G-buffer with an equirectangular environment image through the
// split-sum approximation (a prefiltered environment, an irradiance map and a BRDF
// table). This file gives both sides of that approximation, without any GPU
// discretisation, so a test can tell the split sum's own error from the GPU's:
//   reflected_radiance_integral  the integral the split sum approximates: Monte Carlo
//                                with multiple importance sampling, with its standard error
//   brdf_table, prefiltered_radiance, irradiance, split_sum_radiance
//                                the split sum's three factors and their combination,
//                                each by a deterministic quadrature of stated accuracy
// The BRDF is lab 2's (cpu_reference.h cook_torrance, solutions/02-lighting/brdf.glsl),
// evaluated by calling cook_torrance itself, so its guards are the same.
//
// Conventions (the GPU side uses the same):
//   Equirectangular image `env` (channels 3 or 4, rows top-down, image_io.h), W x H.
//   Texel (x, y) covers u in [x/W, (x+1)/W], v in [y/H, (y+1)/H].
//   Polar angle theta = v pi from +Y (row 0 is the sky overhead), azimuth
//   phi = (u - 0.5) 2 pi; direction = (sin theta sin phi, cos theta, -sin theta cos phi),
//   so u = 0.5 looks towards -Z and u = 0.75 towards +X.
//   L(d), the radiance the image defines, is GL's linear filter on level 0: bilinear
//   between texel centres at (u W - 0.5, v H - 0.5), repeating in u, clamped in v.
//   Roughness is perceptual (glTF), floored at Guards::min_roughness; alpha = roughness^2.
#include <glm/glm.hpp>

#include <cstdint>
#include <vector>

#include "cpu_reference.h"
#include "images/image_io.h"

namespace kit::reference {

using glm::dvec2;

// brdf.glsl cook_torrance: F0 = mix(vec3(0.04), albedo, metallic), the dielectric
// reflectance at normal incidence.
constexpr double KIT_DIELECTRIC_F0 = 0.04;
// shaders/guards.glsl: below this squared length a direction has no
// angles; kit_equirect_uv maps it to the pole overhead.
constexpr double KIT_MIN_DIRECTION_LENGTH_SQUARED = 1e-12;

// --- Equirectangular mapping ------------------------------------------------------------
// The unit direction at image coordinates (u, v) (see the conventions above).
dvec3 equirect_direction(double u, double v);
// The inverse: u = atan2(d.x, -d.z) / (2 pi) + 0.5 in (0, 1], v = acos(clamp(d.y, -1, 1)) / pi.
// d need not be unit length.
dvec2 equirect_uv(dvec3 d);
// Solid angle of any texel of row y, exactly: (2 pi / W)(cos(y pi / H) - cos((y + 1) pi / H)).
double equirect_texel_solid_angle(int y, int width, int height);
// L at image coordinates (u, v): bilinear between texel centres, u repeating, v
// clamped to the edge rows (GL_REPEAT x GL_CLAMP_TO_EDGE, level 0). RGB.
dvec3 environment_radiance_uv(const Image& env, dvec2 uv);
// L(d) = environment_radiance_uv(env, equirect_uv(d)).
dvec3 environment_radiance(const Image& env, dvec3 d);

// --- The reflection integral ------------------------------------------------------------------
// A Monte Carlo estimate of L_o = integral over the sphere of
//   cook_torrance(n, v, l, albedo, metallic, roughness) L(l) max(n.l, 0) d omega_l
// for n = normalize(s.normal), v = normalize(camera_position - s.position). Emission
// is not included.
//
// Sampling: `strategies` picks which of three direction samplers run (all three by
// default); each round draws one direction from each, and the round's value is
// sum_i f(l_i) / sum_j p_j(l_i) over them: the balance heuristic of multiple
// importance sampling with equal sample counts.
//   kSampleGgx          GGX half vectors, pdf_l = D(n.h)(n.h) / (4 v.h) (the specular lobe)
//   kSampleCosine       cosine-weighted hemisphere about n, pdf = (n.l)/pi (the diffuse lobe)
//   kSampleEnvironment  a texel with probability proportional to its luminance times its
//                       solid angle (plus a uniform share, so dark texels are still
//                       sampled), then a direction uniform in solid angle within the
//                       texel; pdf = p_texel / texel solid angle (bright sources). The
//                       luminance is that of L averaged over the texel (weights 1/8, 3/4,
//                       1/8 of each axis' neighbours), so texels next to a bright one,
//                       which the bilinear L brightens, are sampled in proportion.
// A small bright source (a sun) is found by the environment sampler whatever the
// roughness, so its variance stays small where GGX or cosine sampling alone would
// hit it rarely.
//
// Error bound: the rounds are independent and identically distributed, so the
// estimate is their mean and standard_error is the sample standard deviation of the
// round values over sqrt(rounds), per channel. By the central limit theorem
// |value - L_o| < 5 standard_error per channel except with probability ~6e-7; the tests
// use this bound (plus the error of whatever they compare with). The generator is
// splitmix64 seeded with `seed`, so a given call always returns the same estimate.
// Typical relative standard error at 30000 samples: 0.3 % on a smooth environment,
// 1 % with a sun 3000 times the sky (10 to 20 times less than GGX or cosine sampling alone).
// Throws kit::Error for a roughness of 0 with the roughness floor switched off.
enum SamplingStrategy : unsigned {
  kSampleGgx = 1u,
  kSampleCosine = 2u,
  kSampleEnvironment = 4u,
  kSampleAll = kSampleGgx | kSampleCosine | kSampleEnvironment,
};
struct IntegralEstimate {
  dvec3 value{0.0};           // the estimate of L_o, RGB
  dvec3 standard_error{0.0};  // its standard error, RGB
  int samples = 0;            // directions evaluated: rounds x strategies used
};
// `samples` directions in all, rounded up to whole rounds (at least one round).
IntegralEstimate reflected_radiance_integral(const Image& env, const SurfaceSample& s, dvec3 camera_position,
                                             int samples, std::uint64_t seed, const Guards& guards = {},
                                             unsigned strategies = kSampleAll);

// How the IBL tests and kit-bench measure a value against the integral: |a - b| relative
// to max(|b|, floor), the largest channel (the floor keeps dark pixels from dominating).
double relative_error(dvec3 a, dvec3 b, double floor);

// --- The split sum ----------------------------------------------------------------------------
// The BRDF table the lab precomputes, (A, B, C) at n.v = n_dot_v for a view
// v = (sqrt(1 - n_dot_v^2), 0, n_dot_v) above n = (0, 0, 1). With Fc = (1 - v.h)^5 and
// f_s = D G / (4 (n.l)(n.v)) (cook_torrance's specular without F, its guards included):
//   A = integral (1 - Fc) f_s max(n.l, 0) d omega, B = integral Fc f_s max(n.l, 0) d omega,
//   C = (1/pi) integral (1 - Fc) max(n.l, 0) d omega.
// Since F = F0 (1 - Fc) + Fc, the specular part of cook_torrance integrates over a uniform
// environment of radiance 1 to F0 A + B, and the diffuse part (1 - F)(1 - metallic) albedo/pi
// to (1 - metallic) albedo (1 - F0) C.
// Method: A and B by the midpoint rule over the GGX sampling variables, tan(theta_h) =
// alpha tan(psi) (xi = sin^2 psi) and the azimuth phi, 256 x 256 points, where the
// integrand is f / pdf_l = F G (v.h)/((n.v)(n.h)), bounded; each row's azimuth range is
// split where the integrand has a kink or ends (G changing branch, a guard starting,
// n.l = 0), which matters at grazing n.v. C by the midpoint rule over (theta_l, phi),
// 256 x 64 points. Absolute error below 2e-5 at every roughness and n.v down to
// KIT_MIN_N_DOT_V (measured against grids four times finer in each variable; the tests
// check n.v = 1 against 1D integrals). About 15 ms a call.
dvec3 brdf_table(double n_dot_v, double roughness, const Guards& guards = {});

// The prefiltered environment in direction r under Karis' assumption n = v = r:
//   P(r) = integral L(l) D(h) max(r.l, 0) d omega / integral D(h) max(r.l, 0) d omega,
// h = normalize(r + l), D = distribution_ggx at alpha = max(roughness, min_roughness)^2.
// Method: a sum over the environment's texels, each split into kx x ky cells (even
// counts, so that L is bilinear in u, v within a cell) small enough for D: at most a
// twentieth of the lobe's local scale, max(alpha, angle to r / 4), and 0.02 rad. Both
// integrals use the same cells, so a uniform environment gives exactly its radiance.
// Relative error below 2e-4 for every roughness from the 0.045 floor to 1, with a sun
// 3000 times the sky near r, and near 1e-6 on a smooth environment (measured against
// cells four times smaller); as the roughness tends to 0, P(r) tends to L(r). Tens of
// ms a call at 256 x 128, most at low roughness.
dvec3 prefiltered_radiance(const Image& env, dvec3 r, double roughness, const Guards& guards = {});

// The irradiance E(n) = integral L(l) max(n.l, 0) d omega. Method: the same texel sum
// with cells of at most 0.01 rad. Relative error below 1e-4 (a bright source on n's
// horizon is the worst case; ~1e-5 on smooth environments), measured against cells four
// times smaller and, in the tests, against closed forms for a sky and a ground.
dvec3 irradiance(const Image& env, dvec3 n);

// irradiance for many normals under one environment: the texel sum's cells (their
// directions, radiances and solid angles) are found once, so each normal costs a pass of
// dot products instead of the cells' trigonometry and filtering (a 32 x 16 map under
// one environment: 0.6 s instead of 12 s). Each normal gets the very sum irradiance
// gives, term by term in the same order (the tests compare the two bit for bit).
class IrradianceIntegral {
 public:
  explicit IrradianceIntegral(const Image& env);
  dvec3 operator()(dvec3 n) const;

 private:
  struct Cell {
    dvec3 direction, radiance;
    double solid_angle;
  };
  std::vector<Cell> cells_;
};

// The split-sum radiance the lab computes, in double:
//   (F0 A + B) P(r, roughness) + (1 - metallic) albedo (1 - F0) C E(n) / pi
// with F0 = mix(KIT_DIELECTRIC_F0, albedo, metallic), r = reflect(-v, n), and
// (A, B, C) = brdf_table(max(n.v, min_n_dot_v), roughness). n and v as in
// reflected_radiance_integral; emission not included.
dvec3 split_sum_radiance(const Image& env, const SurfaceSample& s, dvec3 camera_position, const Guards& guards = {});

// The same in two steps, for maps other than an environment's (the grader's probes of ibl.frag,
// function_probes.h): where the three factors are looked up (n.v already floored at
// min_n_dot_v, as the table is read), then their combination.
struct SplitSumLookups {
  dvec3 n, v, r;
  double n_dot_v = 0.0;
};
SplitSumLookups split_sum_lookups(const SurfaceSample& s, dvec3 camera_position, const Guards& guards = {});
// (F0 A + B) prefiltered + (1 - metallic) albedo (1 - F0) C irradiance / pi, (A, B, C) = table.
dvec3 split_sum_combination(const SurfaceSample& s, dvec3 table, dvec3 prefiltered, dvec3 irradiance);

}  // namespace kit::reference
