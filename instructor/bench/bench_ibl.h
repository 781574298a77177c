#pragma once
// kit-bench's image-based lighting family (stage 6): ways of precomputing the lab's
// maps, each a point on a speed-against-accuracy chart measured against the
// reflectance integral itself (ibl_reference.h reflected_radiance_integral), not
// against the split sum. What varies: the prefilter's and the BRDF table's sample
// counts, the prefiltered map's size, and how the irradiance map is made
// (irradiance.frag's texel sum, or order-2 spherical harmonics below).
#include <glm/glm.hpp>

#include <array>
#include <string>
#include <vector>

#include "render/ibl.h"
#include "images/image_io.h"

namespace kit::bench {

// --- Irradiance by spherical harmonics (Ramamoorthi and Hanrahan, "An Efficient
// Representation for Irradiance Environment Maps", SIGGRAPH 2001) ------------------------
// The environment projected on the 9 real SH basis functions of bands 0-2; the
// irradiance is then their convolution with the clamped cosine, whose band-l factors
// are pi, 2 pi / 3 and pi / 4 (the cosine lobe's energy beyond band 2 is under 1 %,
// but a small bright source needs the higher bands: it rings and blurs).
constexpr int kSh2Coefficients = 9;
struct Sh2 {
  std::array<glm::dvec3, kSh2Coefficients> coefficients{};  // RGB, in basis order (sh2_basis)
};
// The real SH basis of bands 0-2 at unit direction d: Y00, Y1-1, Y10, Y11, Y2-2, Y2-1,
// Y20, Y21, Y22 with (x, y, z) = d (any orthonormal frame will do: each band is
// rotation-invariant, and projection and evaluation use the same one).
std::array<double, kSh2Coefficients> sh2_basis(glm::dvec3 d);
// Projection in double: the sum over the environment's texels (RGB, rows top-down,
// ibl_reference.h's mapping) of L Y_i at the texel centre times the texel's exact solid angle.
Sh2 project_sh2(const Image& environment);
// E(n) = sum over i of A_l(i) L_i Y_i(n), n a unit vector.
glm::dvec3 sh2_irradiance(const Sh2& sh, glm::dvec3 n);
// An irradiance map of sh2_irradiance at the texel centres, floored at 0, `width` x
// width / 2, RGB rows top-down (what ImageBasedLighting::set_irradiance takes).
Image sh2_irradiance_map(const Sh2& sh, int width);

// --- The methods ----------------------------------------------------------------------------
enum class IrradianceSource {
  Shader,  // the lab's irradiance.frag
  Sh2,     // project_sh2 on the CPU, sh2_irradiance_map uploaded with set_irradiance
};
struct IblMethod {
  std::string name;     // the --method spelling
  std::string summary;  // one line for --list
  IblSettings settings;
  IrradianceSource irradiance = IrradianceSource::Shader;
};
// The family's family name in results.csv.
constexpr const char* kIblFamily = "ibl";
// Every IBL method: "ibl-default" (the lab's settings) first, then sweeps varying one
// setting around it (prefilter samples, BRDF table samples, prefiltered map width), and
// the irradiance map from SH2.
const std::vector<IblMethod>& ibl_methods();
// By name; null when `name` is no IBL method.
const IblMethod* find_ibl_method(const std::string& name);

}  // namespace kit::bench
