#pragma once
// Term probes (function_probes.h, FunctionProbe::given): where the functions a lab function
// calls agree with the reference solution's and the function itself differs, its values at
// inputs chosen to take its terms apart say which term differs and how. Lab 2's cook_torrance
// at a metal (no diffuse lobe), a black dielectric (the specular term alone, F0 = 0.04) and a
// coloured one (less the black one: the diffuse lobe alone), each at l = v (v.h = 1, so
// F = F0) and with h = n at a grazing v.h; lab 3's light_radiance by light type, distance and
// angle; lab 7's light_volume.frag by the shape of a difference across a probe's texels (one
// texel's value at another, a factor of the distance or one factor everywhere). The decision compares the submission's values with the expected ones (probes.json,
// numbers): ratios and differences between cases, never a formula of the lab. It informs and
// never scores.
#include <glm/glm.hpp>

#include <string>
#include <vector>

#include "frames/function_probes.h"  // FunctionProbe

namespace kit::grade {

struct TermDecision {
  std::string term;  // what differs, for naming ("fresnel", "diffuse", ...); "" when nothing fits
  std::string text;  // how, in words, with the values that show it
};

// The decision for a term probe's values (`got`, one per case, finite) against `expected`.
TermDecision decide_terms(const FunctionProbe& probe, const std::vector<glm::vec4>& got, const std::vector<glm::vec4>& expected);

}  // namespace kit::grade
