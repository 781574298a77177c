#include "bench_ibl.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "base/error.h"
#include "ibl_reference.h"

namespace kit::bench {

namespace reference = kit::reference;
using glm::dvec3;

namespace {

// The clamped cosine's SH factors A_l for bands 0, 1, 2 (Ramamoorthi and Hanrahan, eq. 8),
// and the band of each coefficient.
constexpr double kCosineLobe[3] = {reference::KIT_PI, 2.0 * reference::KIT_PI / 3.0, reference::KIT_PI / 4.0};
constexpr int kBand[kSh2Coefficients] = {0, 1, 1, 1, 2, 2, 2, 2, 2};

std::vector<IblMethod> make_ibl_methods() {
  const IblSettings lab;
  std::vector<IblMethod> out;
  out.push_back({"ibl-default",
                 "the lab's maps: prefilter " + std::to_string(lab.prefilter_samples) + " samples at " +
                     std::to_string(lab.prefilter_size) + " wide, BRDF table " + std::to_string(lab.brdf_lut_samples) +
                     " samples, irradiance.frag",
                 lab, IrradianceSource::Shader});
  // Each sweep varies one setting around the lab's.
  const struct {
    const char* prefix;
    int IblSettings::*setting;
    int values[3];
    const char* summary;  // printf format of the value
  } sweeps[] = {
      {"ibl-prefilter", &IblSettings::prefilter_samples, {16, 64, 1024},
       "prefiltered map from %d GGX samples a texel"},
      {"ibl-lut", &IblSettings::brdf_lut_samples, {32, 128, 2048},
       "BRDF table from %d samples a texel (each strategy)"},
      {"ibl-size", &IblSettings::prefilter_size, {64, 128, 512},
       "prefiltered map %d texels wide at level 0"},
  };
  for (const auto& sweep : sweeps)
    for (int value : sweep.values) {
      IblSettings settings;
      settings.*sweep.setting = value;
      char summary[128];
      std::snprintf(summary, sizeof summary, sweep.summary, value);
      out.push_back({sweep.prefix + std::to_string(value), summary, settings, IrradianceSource::Shader});
    }
  out.push_back({"ibl-sh2",
                 "irradiance map from order-2 spherical harmonics (9 coefficients, projected on the CPU in double)", lab,
                 IrradianceSource::Sh2});
  return out;
}

}  // namespace

std::array<double, kSh2Coefficients> sh2_basis(dvec3 d) {
  // Normalisation constants: sqrt(1 / 4pi), sqrt(3 / 4pi), sqrt(15 / 4pi), sqrt(5 / 16pi), sqrt(15 / 16pi).
  const double pi = reference::KIT_PI;
  const double c0 = std::sqrt(1.0 / (4.0 * pi)), c1 = std::sqrt(3.0 / (4.0 * pi)), c2 = std::sqrt(15.0 / (4.0 * pi));
  const double c3 = std::sqrt(5.0 / (16.0 * pi)), c4 = std::sqrt(15.0 / (16.0 * pi));
  return {c0,
          c1 * d.y,
          c1 * d.z,
          c1 * d.x,
          c2 * d.x * d.y,
          c2 * d.y * d.z,
          c3 * (3.0 * d.z * d.z - 1.0),
          c2 * d.x * d.z,
          c4 * (d.x * d.x - d.y * d.y)};
}

Sh2 project_sh2(const Image& environment) {
  if (environment.channels < 3 || environment.width < 1 || environment.height < 1)
    throw Error("project_sh2 needs an RGB environment of at least one texel");
  Sh2 sh;
  const int width = environment.width, height = environment.height;
  for (int y = 0; y < height; ++y) {
    const double solid_angle = reference::equirect_texel_solid_angle(y, width, height);
    for (int x = 0; x < width; ++x) {
      const dvec3 d = reference::equirect_direction((x + 0.5) / width, (y + 0.5) / height);
      const dvec3 radiance(environment.at(x, y, 0), environment.at(x, y, 1), environment.at(x, y, 2));
      const auto basis = sh2_basis(d);
      for (int i = 0; i < kSh2Coefficients; ++i) sh.coefficients[i] += radiance * (basis[i] * solid_angle);
    }
  }
  return sh;
}

dvec3 sh2_irradiance(const Sh2& sh, dvec3 n) {
  const auto basis = sh2_basis(n);
  dvec3 e(0.0);
  for (int i = 0; i < kSh2Coefficients; ++i) e += sh.coefficients[i] * (kCosineLobe[kBand[i]] * basis[i]);
  return e;
}

Image sh2_irradiance_map(const Sh2& sh, int width) {
  const int height = std::max(width / 2, 1);
  Image map(width, height, 3);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const dvec3 e = sh2_irradiance(sh, reference::equirect_direction((x + 0.5) / width, (y + 0.5) / height));
      // Truncated at band 2 the series rings below 0 opposite a bright source; light cannot.
      for (int c = 0; c < 3; ++c) map.at(x, y, c) = static_cast<float>(std::max(e[c], 0.0));
    }
  return map;
}

const std::vector<IblMethod>& ibl_methods() {
  static const std::vector<IblMethod> all = make_ibl_methods();
  return all;
}

const IblMethod* find_ibl_method(const std::string& name) {
  for (const IblMethod& m : ibl_methods())
    if (m.name == name) return &m;
  return nullptr;
}

}  // namespace kit::bench
