#include "ibl_reference.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "base/error.h"

namespace kit::reference {

namespace {

// --- Named constants of the methods (each explained where it is used) --------------------

// Environment sampling: share of the texel probability spread uniformly over the
// sphere, so that texels darker than their surroundings are still sampled.
constexpr double kEnvironmentUniformShare = 0.05;
// Weights of texels x-1, x, x+1 in the integral of the bilinear L over texel x's
// extent (per axis): its half-texel bands blend in the neighbours' centres.
constexpr double kTexelFootprint[3] = {0.125, 0.75, 0.125};

// brdf_table's grids: midpoint rule, polar steps x azimuth steps over [0, pi]. The
// specular integrand has kinks close together at grazing n.v; the diffuse one is smooth.
// 512 polar steps hold the table within 1e-5 of a one-dimensional quadrature at n.v = 1
// for the lecture's G and for Smith's with Schlick-GGX (instructor/changing_a_lab/), whose
// G1 rises with slope 1/k from the horizon: 256 left it 5.6e-5 off at roughness 0.3.
constexpr int kTablePolarSteps = 512;
constexpr int kTableSpecularAzimuthSteps = 256;
constexpr int kTableDiffuseAzimuthSteps = 64;
constexpr int kTableMinPieceSteps = 4;  // on a piece of the azimuth range however short

// Texel sums: largest cell, in radians, where the weight is smooth on the texel's scale
// (irradiance's cosine), and where it is GGX's D (prefiltered_radiance), whose cells
// are also at most kLobeCellFraction of the lobe's local scale.
constexpr double kIrradianceCellAngle = 0.01;
constexpr double kPrefilterCellAngle = 0.02;
constexpr double kLobeCellFraction = 0.05;
// Cells per texel side at most, whatever the lobe (a lobe narrower than a texel over
// this is below the stated range of roughness).
constexpr int kMaxCellsPerTexelSide = 256;

constexpr double kTwoPi = 2.0 * KIT_PI;

// Rec. 709 luminance with math.glsl's KIT_LUMINANCE weights: the environment sampler's
// measure of a texel's brightness.
double luminance(dvec3 rgb) { return KIT_LUMINANCE[0] * rgb.x + KIT_LUMINANCE[1] * rgb.y + KIT_LUMINANCE[2] * rgb.z; }

// Texel (x, y)'s RGB in double; a fourth channel is ignored.
dvec3 texel_rgb(const Image& env, int x, int y) { return {env.at(x, y, 0), env.at(x, y, 1), env.at(x, y, 2)}; }

// The equirectangular direction at polar angle theta (given by its cosine and sine)
// and azimuth phi (by its cosine and sine, or itself); equirect_direction, the texel
// sums and the environment sampler share it.
dvec3 polar_direction(double cos_theta, double sin_theta, double cos_phi, double sin_phi) {
  return {sin_theta * sin_phi, cos_theta, -sin_theta * cos_phi};
}
dvec3 polar_direction(double cos_theta, double sin_theta, double phi) {
  return polar_direction(cos_theta, sin_theta, std::cos(phi), std::sin(phi));
}

// x modulo `width` into [0, width): GL_REPEAT on texel indices.
int wrap(int x, int width) {
  const int m = x % width;
  return m < 0 ? m + width : m;
}

// Every public function reads the image through at(): refuse one too small to index.
void require_environment(const Image& env) {
  if (env.width < 1 || env.height < 1 || env.channels < 3 ||
      env.pixels.size() != static_cast<size_t>(env.width) * env.height * env.channels)
    throw Error("an environment image needs at least one texel and 3 or 4 channels");
}

// Smallest even count of cells that splits `extent` radians into cells of at most `cell`
// radians (even, so that the texel centre lines, where the bilinear L has its kinks,
// are cell edges).
int even_cells(double extent, double cell) {
  const double n = std::ceil(extent / cell);
  const int cells = n > kMaxCellsPerTexelSide ? kMaxCellsPerTexelSide : static_cast<int>(n);
  return std::max(2, cells + cells % 2);
}

// The midpoint rule over the environment's texels: texel (x, y) is split into
// kx x ky cells of equal u and v extent, with kx, ky the smallest even counts making
// every cell at most cell_angle(centre, radius) radians wide (centre: the texel centre's
// direction, radius: a bound on the angle from it to any point of the texel); a texel
// whose cell_angle is 0 or less is skipped. visit(u, v, direction, solid_angle) is called
// at each cell's centre in (u, v), with equirect_direction(u, v) and the cell's exact solid
// angle. Within a cell L is bilinear in (u, v), so the error is that of the midpoint rule
// on the smooth weight times a bilinear function: second order in the cell size.
// The directions' sines and cosines are found once per row (theta) and column (phi) of
// cells or texel centres, not per cell or texel: the same values equirect_direction
// computes, so the sums are the same to the bit, at a fraction of the trigonometry.
template <typename CellAngle, typename Visit>
void for_each_texel_cell(int width, int height, CellAngle cell_angle, Visit visit) {
  const double texel_phi = kTwoPi / width;
  const double texel_theta = KIT_PI / height;
  double cell_u[kMaxCellsPerTexelSide], sin_phi[kMaxCellsPerTexelSide], cos_phi[kMaxCellsPerTexelSide];
  // The texel centres' azimuths, the same in every row.
  std::vector<double> centre_sin_phi(width), centre_cos_phi(width);
  for (int x = 0; x < width; ++x) {
    const double phi = ((x + 0.5) / width - 0.5) * kTwoPi;  // as equirect_direction
    centre_sin_phi[x] = std::sin(phi);
    centre_cos_phi[x] = std::cos(phi);
  }
  for (int y = 0; y < height; ++y) {
    const double theta0 = y * texel_theta, theta1 = (y + 1) * texel_theta;
    // Widest sine of the row: at the equator if the row straddles it.
    const double widest = (theta0 <= 0.5 * KIT_PI && theta1 >= 0.5 * KIT_PI) ? 1.0
                                                                             : std::max(std::sin(theta0), std::sin(theta1));
    const double width_angle = widest * texel_phi;
    // No point of a texel is farther from its centre than half its height along a meridian
    // plus half its widest width along a parallel.
    const double radius = 0.5 * (width_angle + texel_theta);
    const double centre_theta = (y + 0.5) / height * KIT_PI;  // as equirect_direction
    const double centre_cos_theta = std::cos(centre_theta), centre_sin_theta = std::sin(centre_theta);
    for (int x = 0; x < width; ++x) {
      const dvec3 centre = polar_direction(centre_cos_theta, centre_sin_theta, centre_cos_phi[x], centre_sin_phi[x]);
      const double cell = cell_angle(centre, radius);
      if (!(cell > 0.0)) continue;
      const int kx = even_cells(width_angle, cell), ky = even_cells(texel_theta, cell);
      for (int i = 0; i < kx; ++i) {
        cell_u[i] = (x + (i + 0.5) / kx) / width;
        const double phi = (cell_u[i] - 0.5) * kTwoPi;  // as equirect_direction
        sin_phi[i] = std::sin(phi);
        cos_phi[i] = std::cos(phi);
      }
      double ct0 = std::cos(theta0);  // the cosine at the cell row's top edge
      for (int j = 0; j < ky; ++j) {
        const double ct1 = std::cos(theta0 + (j + 1) * texel_theta / ky);
        const double solid_angle = texel_phi / kx * (ct0 - ct1);
        const double v = (y + (j + 0.5) / ky) / height;
        const double theta = v * KIT_PI;  // as equirect_direction
        const double cos_theta = std::cos(theta), sin_theta = std::sin(theta);
        for (int i = 0; i < kx; ++i)
          visit(cell_u[i], v, polar_direction(cos_theta, sin_theta, cos_phi[i], sin_phi[i]), solid_angle);
        ct0 = ct1;
      }
    }
  }
}

// GGX's alpha as cook_torrance forms it: the perceptual roughness floored at
// guards.min_roughness, squared. A mirror (alpha 0, only with the floor switched off) has
// no finite D to integrate or sample.
double ggx_alpha(double roughness, const Guards& guards) {
  const double floored = std::max(roughness, guards.min_roughness);
  if (!(floored > 0.0)) throw Error("the IBL reference needs a roughness above 0 (a mirror has no finite GGX lobe)");
  return floored * floored;
}

// Angle in radians between unit vectors a and b.
double angle_between(dvec3 a, dvec3 b) { return std::acos(std::clamp(glm::dot(a, b), -1.0, 1.0)); }

// The midpoint rule for integral over x in [0, pi/2], phi in [0, pi] of
// sin(2x) f(x, phi) dx dphi / pi: brdf_table's integrals, written over a polar variable x
// whose measure is sin(2x) dx (the cosine-weighted or the GGX-sampled hemisphere) and an
// azimuth folded onto [0, pi] (the integrands are symmetric about the plane of n and v).
// pieces(x, breaks) fills the azimuths 0 = b_0 < b_1 < ... < b_k <= pi of row x between
// which f is smooth (f is 0 past b_k); each piece gets its own midpoint rule, so a
// kink or a cut of f costs no accuracy. f returns a double or a glm vector.
template <typename Pieces, typename F>
auto polar_grid_mean(int azimuth_steps, Pieces pieces, F f) {
  using Value = decltype(f(0.0, 0.0));
  Value sum(0.0);
  std::vector<double> breaks;
  for (int i = 0; i < kTablePolarSteps; ++i) {
    const double x = (i + 0.5) * 0.5 * KIT_PI / kTablePolarSteps;
    breaks.assign(1, 0.0);
    pieces(x, breaks);
    Value row(0.0);  // integral over phi of f(x, phi)
    for (size_t k = 0; k + 1 < breaks.size(); ++k) {
      const double length = breaks[k + 1] - breaks[k];
      if (!(length > 0.0)) continue;
      const int steps = std::max(kTableMinPieceSteps, static_cast<int>(std::ceil(azimuth_steps * length / KIT_PI)));
      Value piece(0.0);
      for (int j = 0; j < steps; ++j) piece += f(x, breaks[k] + (j + 0.5) * length / steps);
      row += piece * (length / steps);
    }
    sum += std::sin(2.0 * x) * row;
  }
  // sum_i sin(2 x_i) (pi/2)/N is the midpoint rule for integral sin(2x) dx = 1.
  return sum * (0.5 / kTablePolarSteps);
}

// brdf_table's specular pieces for the half vectors at polar angle theta_h (cosine c,
// sine s) about n = (0, 0, 1), v = (sv, 0, mu): with v.h = sv s cos(phi) + mu c and
// l.z = 2 (v.h) c - mu, both decreasing in phi, the integrand is 0 where l.z <= 0
// (past phi_cut) and has kinks where l.z or v.h cross a guard or a change of branch of
// G = min(1, 2 c n.v / v.h, 2 c n.l / v.h) (n.l = n.v, v.h = 2 c n.v, v.h = 2 c n.l).
void specular_pieces(double mu, double c, double s, const Guards& guards, std::vector<double>& breaks) {
  const double sv = std::sqrt(1.0 - mu * mu);
  const double spread = sv * s;  // d(v.h)/d(cos phi)
  const double n_dot_v = std::max(mu, guards.min_n_dot_v);
  if (!(spread > 0.0) || !(c > 0.0)) {  // no dependence on phi
    if (2.0 * mu * c * c - mu > 0.0) breaks.push_back(KIT_PI);
    return;
  }
  // The azimuth at which v.h = target, or 0 / pi where it is reached nowhere inside.
  auto where_v_dot_h = [&](double target) { return std::acos(std::clamp((target - mu * c) / spread, -1.0, 1.0)); };
  auto where_n_dot_l = [&](double target) { return where_v_dot_h((target + mu) / (2.0 * c)); };
  const double cut = where_n_dot_l(0.0);
  std::vector<double> kinks = {where_n_dot_l(n_dot_v), where_n_dot_l(guards.min_n_dot_l),
                               where_n_dot_l(guards.min_denominator / (4.0 * n_dot_v)),
                               where_v_dot_h(2.0 * c * n_dot_v), where_v_dot_h(guards.min_v_dot_h),
                               where_v_dot_h(0.5 * std::sqrt(std::max(guards.min_denominator, 0.0)))};
  // v.h = 2 c n.l with n.l = 2 (v.h) c - mu: v.h (4 c^2 - 1) = 2 c mu.
  if (4.0 * c * c > 1.0) kinks.push_back(where_v_dot_h(2.0 * c * mu / (4.0 * c * c - 1.0)));
  std::sort(kinks.begin(), kinks.end());
  for (double k : kinks)
    if (k > breaks.back() && k < cut) breaks.push_back(k);
  if (cut > 0.0) breaks.push_back(cut);
}

// GGX half-vector sampling pdf of l (in solid angle), D(n.h)(n.h)/(4 |v.h|) with
// h = normalize(v + l); D is the exact (unguarded) GGX, the density the sampler draws.
// The sampler draws n.h > 0; |.| covers an l whose v + l points below the surface,
// reached by the opposite half vector.
double ggx_pdf(dvec3 n, dvec3 v, dvec3 l, double alpha) {
  const dvec3 half_sum = v + l;
  const double length2 = glm::dot(half_sum, half_sum);
  if (!(length2 > 0.0)) return 0.0;
  const dvec3 h = half_sum / std::sqrt(length2);
  const double n_dot_h = std::fabs(glm::dot(n, h));
  const double v_dot_h = std::fabs(glm::dot(v, h));
  if (!(v_dot_h > 0.0)) return 0.0;
  return distribution_ggx(n_dot_h, alpha, Guards::none()) * n_dot_h / (4.0 * v_dot_h);
}

// cos(theta_h) and sin(theta_h) of the GGX half vector at tan(theta_h) = alpha tan(psi):
// the GGX sample at xi = sin^2(psi) (cos^2 theta_h = (1 - xi)/(1 + (alpha^2 - 1) xi)),
// written without the cancellation of 1 - xi near xi = 1.
dvec2 ggx_half_angle(double psi, double alpha) {
  const double c = std::cos(psi), s = std::sin(psi);
  const double norm = std::sqrt(c * c + alpha * alpha * s * s);
  return {c / norm, alpha * s / norm};
}

// splitmix64 (Steele, Lea and Flood 2014): a seeded 64-bit generator, so estimates
// are reproducible; uniform() takes its top 53 bits as a double in [0, 1).
struct SplitMix64 {
  std::uint64_t state;
  std::uint64_t next() {
    std::uint64_t z = (state += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
  }
  double uniform() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }
};

// The environment sampler of reflected_radiance_integral: texel probabilities
// proportional to the luminance of the bilinear L integrated over the texel's (u, v)
// rectangle (kTexelFootprint) times its solid angle, mixed with a uniform share.
class EnvironmentSampler {
 public:
  explicit EnvironmentSampler(const Image& env) : width_(env.width), height_(env.height) {
    const int w = width_, h = height_;
    std::vector<double> texel_luminance(static_cast<size_t>(w) * h);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) texel_luminance[static_cast<size_t>(y) * w + x] = std::max(0.0, luminance(texel_rgb(env, x, y)));
    solid_angle_.resize(h);
    for (int y = 0; y < h; ++y) solid_angle_[y] = equirect_texel_solid_angle(y, w, h);
    // Luminance of L over each texel: separable footprint, repeating in x, clamped in y.
    probability_.assign(texel_luminance.size(), 0.0);
    double total = 0.0;
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x) {
        double footprint = 0.0;
        for (int dy = -1; dy <= 1; ++dy)
          for (int dx = -1; dx <= 1; ++dx)
            footprint += kTexelFootprint[dy + 1] * kTexelFootprint[dx + 1] *
                         texel_luminance[static_cast<size_t>(std::clamp(y + dy, 0, h - 1)) * w + wrap(x + dx, w)];
        probability_[static_cast<size_t>(y) * w + x] = footprint * solid_angle_[y];
        total += footprint * solid_angle_[y];
      }
    }
    const double uniform_share = total > 0.0 ? kEnvironmentUniformShare : 1.0;
    cdf_.resize(probability_.size());
    double running = 0.0;
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x) {
        double& p = probability_[static_cast<size_t>(y) * w + x];
        p = (total > 0.0 ? (1.0 - uniform_share) * p / total : 0.0) + uniform_share * solid_angle_[y] / (2.0 * kTwoPi);
        running += p;
        cdf_[static_cast<size_t>(y) * w + x] = running;
      }
    }
  }

  // A texel by the CDF (uniform a), then u uniform (b) and cos(theta) uniform (c)
  // within it: a direction uniform in solid angle over the texel.
  dvec3 sample(double a, double b, double c) const {
    const double target = a * cdf_.back();
    const size_t index = std::min(static_cast<size_t>(std::upper_bound(cdf_.begin(), cdf_.end(), target) - cdf_.begin()),
                                  cdf_.size() - 1);
    const int x = static_cast<int>(index % width_), y = static_cast<int>(index / width_);
    const double cos0 = std::cos(y * KIT_PI / height_), cos1 = std::cos((y + 1) * KIT_PI / height_);
    const double cos_theta = cos0 + c * (cos1 - cos0);
    const double phi = ((x + b) / width_ - 0.5) * kTwoPi;
    return polar_direction(cos_theta, std::sqrt(std::max(0.0, 1.0 - cos_theta * cos_theta)), phi);
  }

  // The density in solid angle of sample(): the texel's probability over its solid angle.
  double pdf(dvec3 l) const {
    const dvec2 uv = equirect_uv(l);
    const int x = std::min(static_cast<int>(uv.x * width_), width_ - 1);
    const int y = std::min(static_cast<int>(uv.y * height_), height_ - 1);
    return probability_[static_cast<size_t>(y) * width_ + x] / solid_angle_[y];
  }

 private:
  int width_, height_;
  std::vector<double> solid_angle_;  // per row
  std::vector<double> probability_;  // per texel, summing to 1
  std::vector<double> cdf_;          // running sums of probability_, row-major
};

}  // namespace

// --- Equirectangular mapping ------------------------------------------------------------

dvec3 equirect_direction(double u, double v) {
  const double theta = v * KIT_PI;
  return polar_direction(std::cos(theta), std::sin(theta), (u - 0.5) * kTwoPi);
}

dvec2 equirect_uv(dvec3 d) {
  // kit_equirect_uv's guard (guards.glsl): a zero vector has no angles (0/0); it maps to the pole overhead.
  if (glm::dot(d, d) < KIT_MIN_DIRECTION_LENGTH_SQUARED) return {0.5, 0.0};
  const double length = glm::length(d);
  // Straight up or down, kit_equirect_uv's azimuth: 0 (atan2 would give 0 or pi by the zeros' signs).
  const double phi = d.x == 0.0 && d.z == 0.0 ? 0.0 : std::atan2(d.x, -d.z);
  const double theta = std::acos(std::clamp(d.y / length, -1.0, 1.0));
  return {phi / kTwoPi + 0.5, theta / KIT_PI};
}

double equirect_texel_solid_angle(int y, int width, int height) {
  return kTwoPi / width * (std::cos(y * KIT_PI / height) - std::cos((y + 1) * KIT_PI / height));
}

dvec3 environment_radiance_uv(const Image& env, dvec2 uv) {
  // Texel centres sit at integer coordinates of (u W - 0.5, v H - 0.5).
  const double fx = uv.x * env.width - 0.5, fy = uv.y * env.height - 0.5;
  const double x_floor = std::floor(fx), y_floor = std::floor(fy);
  const double tx = fx - x_floor, ty = fy - y_floor;
  const int x0 = wrap(static_cast<int>(x_floor), env.width), x1 = wrap(static_cast<int>(x_floor) + 1, env.width);
  const int y0 = std::clamp(static_cast<int>(y_floor), 0, env.height - 1);
  const int y1 = std::clamp(static_cast<int>(y_floor) + 1, 0, env.height - 1);
  const dvec3 top = glm::mix(texel_rgb(env, x0, y0), texel_rgb(env, x1, y0), tx);
  const dvec3 bottom = glm::mix(texel_rgb(env, x0, y1), texel_rgb(env, x1, y1), tx);
  return glm::mix(top, bottom, ty);
}

dvec3 environment_radiance(const Image& env, dvec3 d) { return environment_radiance_uv(env, equirect_uv(d)); }

// --- The reflection integral ------------------------------------------------------------------

IntegralEstimate reflected_radiance_integral(const Image& env, const SurfaceSample& s, dvec3 camera_position,
                                             int samples, std::uint64_t seed, const Guards& guards,
                                             unsigned strategies) {
  require_environment(env);
  strategies &= kSampleAll;
  if (strategies == 0) throw Error("reflected_radiance_integral needs at least one sampling strategy");
  const bool use_ggx = strategies & kSampleGgx, use_cosine = strategies & kSampleCosine;
  const bool use_environment = strategies & kSampleEnvironment;
  const int per_round = int{use_ggx} + int{use_cosine} + int{use_environment};
  const int rounds = std::max(1, (samples + per_round - 1) / per_round);

  const dvec3 n = glm::normalize(s.normal);
  const dvec3 v = glm::normalize(camera_position - s.position);
  const double alpha = ggx_alpha(s.roughness, guards);
  const dvec3 tangent = any_perpendicular(n);
  const dvec3 bitangent = glm::cross(n, tangent);
  // An empty sampler when unused: building one reads the whole image.
  const EnvironmentSampler environment = use_environment ? EnvironmentSampler(env) : EnvironmentSampler(Image(1, 1, 3));

  // The integrand f(l) = cook_torrance L(l) max(n.l, 0).
  auto integrand = [&](dvec3 l) {
    const double n_dot_l = glm::dot(n, l);
    if (!(n_dot_l > 0.0)) return dvec3(0.0);
    return cook_torrance(n, v, l, s.albedo, s.metallic, s.roughness, guards) * environment_radiance(env, l) * n_dot_l;
  };
  // sum_j p_j(l) over the strategies in use: the balance heuristic's denominator.
  auto pdf_sum = [&](dvec3 l) {
    double p = 0.0;
    if (use_ggx) p += ggx_pdf(n, v, l, alpha);
    if (use_cosine) p += std::max(glm::dot(n, l), 0.0) / KIT_PI;
    if (use_environment) p += environment.pdf(l);
    return p;
  };
  auto in_frame = [&](double sin_theta, double cos_theta, double phi) {
    return tangent * (sin_theta * std::cos(phi)) + bitangent * (sin_theta * std::sin(phi)) + n * cos_theta;
  };

  SplitMix64 rng{seed};
  dvec3 mean(0.0), squares(0.0);  // Welford's running mean and sum of squared deviations
  for (int round = 0; round < rounds; ++round) {
    dvec3 value(0.0);
    auto add = [&](dvec3 l) {
      const dvec3 f = integrand(l);
      if (f == dvec3(0.0)) return;
      const double p = pdf_sum(l);
      if (p > 0.0) value += f / p;
    };
    if (use_ggx) {
      // GGX half vector (cos^2 theta_h = (1 - xi)/(1 + (alpha^2 - 1) xi)), then l = reflect(-v, h).
      const double xi = rng.uniform(), phi = kTwoPi * rng.uniform();
      const double cos2 = (1.0 - xi) / (1.0 + (alpha * alpha - 1.0) * xi);
      const dvec3 h = in_frame(std::sqrt(std::max(0.0, 1.0 - cos2)), std::sqrt(cos2), phi);
      add(glm::normalize(2.0 * glm::dot(v, h) * h - v));
    }
    if (use_cosine) {
      // Malley's method: a uniform point on the disc, projected up to the hemisphere.
      const double xi = rng.uniform(), phi = kTwoPi * rng.uniform();
      add(in_frame(std::sqrt(xi), std::sqrt(1.0 - xi), phi));
    }
    if (use_environment) {
      const double a = rng.uniform(), b = rng.uniform(), c = rng.uniform();
      add(environment.sample(a, b, c));
    }
    const dvec3 delta = value - mean;
    mean += delta / static_cast<double>(round + 1);
    squares += delta * (value - mean);
  }

  IntegralEstimate estimate;
  estimate.value = mean;
  estimate.samples = rounds * per_round;
  if (rounds > 1) estimate.standard_error = glm::sqrt(squares / static_cast<double>(rounds - 1) / static_cast<double>(rounds));
  else estimate.standard_error = dvec3(std::numeric_limits<double>::infinity());
  return estimate;
}

// --- The split sum ----------------------------------------------------------------------------

double relative_error(dvec3 a, dvec3 b, double floor) {
  const dvec3 e = glm::abs(a - b) / glm::max(glm::abs(b), dvec3(floor));
  return std::max(e.x, std::max(e.y, e.z));
}

dvec3 brdf_table(double n_dot_v, double roughness, const Guards& guards) {
  const double mu = std::clamp(n_dot_v, 0.0, 1.0);
  const dvec3 n(0.0, 0.0, 1.0);
  const dvec3 v(std::sqrt(1.0 - mu * mu), 0.0, mu);
  const double alpha = ggx_alpha(roughness, guards);
  // cook_torrance evaluated once with albedo (1, 0, 0) gives albedo 1 in red and 0 in green.
  const dvec3 red(1.0, 0.0, 0.0);

  // Specular: cook_torrance at metallic 1 is F f_s with F0 = albedo, so red is f_s (F = 1)
  // and green Fc f_s. Over the GGX sampling variables (xi = sin^2 psi, phi) the measure
  // of l is pdf_l d omega, and f / pdf_l = F G (v.h)/((n.v)(n.h)) is bounded.
  const dvec2 specular = polar_grid_mean(
      kTableSpecularAzimuthSteps,
      [&](double psi, std::vector<double>& breaks) {
        const dvec2 half_angle = ggx_half_angle(psi, alpha);
        specular_pieces(mu, half_angle.x, half_angle.y, guards, breaks);
      },
      [&](double psi, double phi) {
        const dvec2 half_angle = ggx_half_angle(psi, alpha);
        const dvec3 h(half_angle.y * std::cos(phi), half_angle.y * std::sin(phi), half_angle.x);
        const double v_dot_h = glm::dot(v, h);
        const dvec3 l = 2.0 * v_dot_h * h - v;
        if (!(v_dot_h > 0.0) || !(l.z > 0.0)) return dvec2(0.0);
        const double pdf = distribution_ggx(half_angle.x, alpha, Guards::none()) * half_angle.x / (4.0 * v_dot_h);
        const dvec3 f = cook_torrance(n, v, l, red, 1.0, roughness, guards) * (l.z / pdf);
        return dvec2(f.x - f.y, f.y);  // (1 - Fc) f_s, Fc f_s
      });

  // Diffuse: at metallic 0 F0 = KIT_DIELECTRIC_F0 in every channel, so red minus green is
  // the diffuse term (1 - F)/pi, and 1 - F = (1 - F0)(1 - Fc). Over the cosine-weighted
  // hemisphere (x = theta_l) the measure of l is (n.l)/pi d omega.
  const double c_mean = polar_grid_mean(
      kTableDiffuseAzimuthSteps, [](double, std::vector<double>& breaks) { breaks.push_back(KIT_PI); },
      [&](double theta, double phi) {
        const dvec3 l(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta));
        const dvec3 f = cook_torrance(n, v, l, red, 0.0, roughness, guards);
        return (f.x - f.y) * KIT_PI / (1.0 - KIT_DIELECTRIC_F0);
      });
  return {specular.x, specular.y, c_mean};
}

dvec3 prefiltered_radiance(const Image& env, dvec3 r, double roughness, const Guards& guards) {
  require_environment(env);
  r = glm::normalize(r);
  const double alpha = ggx_alpha(roughness, guards);
  dvec3 weighted(0.0);
  double weight = 0.0;
  for_each_texel_cell(
      env.width, env.height,
      [&](dvec3 centre, double radius) {
        const double nearest = std::max(0.0, angle_between(r, centre) - radius);
        if (nearest >= 0.5 * KIT_PI) return 0.0;  // wholly behind r: max(r.l, 0) = 0
        // D(h) at angle t from r (h at t/2) varies on the scale alpha near the peak and t/4 in the tail.
        return std::min(kPrefilterCellAngle, kLobeCellFraction * std::max(alpha, 0.25 * nearest));
      },
      [&](double u, double v, dvec3 l, double solid_angle) {
        const double r_dot_l = glm::dot(r, l);
        if (!(r_dot_l > 0.0)) return;
        const dvec3 h = glm::normalize(r + l);
        const double w = distribution_ggx(std::clamp(glm::dot(r, h), 0.0, 1.0), alpha, guards) * r_dot_l * solid_angle;
        weighted += w * environment_radiance_uv(env, {u, v});
        weight += w;
      });
  return weight > 0.0 ? weighted / weight : environment_radiance(env, r);
}

IrradianceIntegral::IrradianceIntegral(const Image& env) {
  require_environment(env);
  // Every cell, also those irradiance skips as wholly behind its n: their terms have
  // n.l <= 0, so operator() skips them term by term and adds what irradiance adds.
  for_each_texel_cell(
      env.width, env.height, [](dvec3, double) { return kIrradianceCellAngle; },
      [&](double u, double v, dvec3 l, double solid_angle) {
        cells_.push_back({l, environment_radiance_uv(env, {u, v}), solid_angle});
      });
}

dvec3 IrradianceIntegral::operator()(dvec3 n) const {
  n = glm::normalize(n);
  dvec3 sum(0.0);
  for (const Cell& c : cells_) {
    const double n_dot_l = glm::dot(n, c.direction);
    if (n_dot_l > 0.0) sum += c.radiance * (n_dot_l * c.solid_angle);
  }
  return sum;
}

// One normal alone: the cells wholly behind n are skipped before their directions and
// radiances are computed, so a single call costs half of building IrradianceIntegral.
dvec3 irradiance(const Image& env, dvec3 n) {
  require_environment(env);
  n = glm::normalize(n);
  dvec3 sum(0.0);
  for_each_texel_cell(
      env.width, env.height,
      [&](dvec3 centre, double radius) {
        return angle_between(n, centre) - radius >= 0.5 * KIT_PI ? 0.0 : kIrradianceCellAngle;
      },
      [&](double u, double v, dvec3 l, double solid_angle) {
        const double n_dot_l = glm::dot(n, l);
        if (n_dot_l > 0.0) sum += environment_radiance_uv(env, {u, v}) * (n_dot_l * solid_angle);
      });
  return sum;
}

SplitSumLookups split_sum_lookups(const SurfaceSample& s, dvec3 camera_position, const Guards& guards) {
  SplitSumLookups at;
  at.n = glm::normalize(s.normal);
  at.v = glm::normalize(camera_position - s.position);
  at.r = glm::reflect(-at.v, at.n);
  at.n_dot_v = std::max(glm::dot(at.n, at.v), guards.min_n_dot_v);
  return at;
}

dvec3 split_sum_combination(const SurfaceSample& s, dvec3 table, dvec3 prefiltered, dvec3 irradiance) {
  const dvec3 f0 = glm::mix(dvec3(KIT_DIELECTRIC_F0), s.albedo, s.metallic);
  const dvec3 specular = (f0 * table.x + table.y) * prefiltered;
  const dvec3 diffuse = (1.0 - s.metallic) * s.albedo * (1.0 - f0) * table.z * irradiance / KIT_PI;
  return specular + diffuse;
}

dvec3 split_sum_radiance(const Image& env, const SurfaceSample& s, dvec3 camera_position, const Guards& guards) {
  const SplitSumLookups at = split_sum_lookups(s, camera_position, guards);
  return split_sum_combination(s, brdf_table(at.n_dot_v, s.roughness, guards), prefiltered_radiance(env, at.r, s.roughness, guards),
                               irradiance(env, at.n));
}

}  // namespace kit::reference
