// Named guards that keep the shading math finite (in the style of Filament): every
// numeric floor of the framework's and the labs' shaders. handouts/02-lighting.md,
// 03-attenuation.md, 04-normalmap.md and 06-ibl.md explain each one.

// n.v and n.l are floored in the specular denominator 4 (n.l)(n.v): at a
// silhouette or a grazing light they reach 0 and the quotient blows up.
const float KIT_MIN_N_DOT_V = 1e-4;
const float KIT_MIN_N_DOT_L = 1e-4;
// v.h is floored where the geometry term divides by it.
const float KIT_MIN_V_DOT_H = 1e-4;
// Minimum perceptual roughness: alpha = roughness^2 >= 0.002, so GGX D at n.h = 1
// is 1/(pi alpha^2) and never 0/0.
const float KIT_MIN_ROUGHNESS = 0.045;
// Floor under every other denominator.
const float KIT_MIN_DENOMINATOR = 1e-7;
// Floor under GGX's denominator pi ((n.h)^2 (alpha^2 - 1) + 1)^2. With the roughness
// floor it is at least pi KIT_MIN_ROUGHNESS^8 = 5.3e-11 (at n.h = 1), so this floor
// must stay below that: KIT_MIN_DENOMINATOR (1e-7) there would cap D of every
// roughness under 0.115 near its peak (at 41 instead of 1/(pi alpha^2) = 77625 for
// roughness 0.045). It only keeps alpha = 0 from dividing by zero.
const float KIT_MIN_GGX_DENOMINATOR = 1e-12;
// Floor under r^2 in inverse-square falloff: a light sitting on a surface
// stays finite (1 cm squared).
const float KIT_MIN_DISTANCE_SQUARED = 1e-4;
// Smallest cosine gap between a spot's inner and outer cone, so a zero-width
// falloff (inner == outer) is a hard edge instead of a division by zero.
const float KIT_MIN_CONE_COS_GAP = 1e-4;
// Floor under the spot normalisation 1 - (cos_inner + cos_outer)/2.
const float KIT_MIN_SPOT_SOLID_ANGLE = 1e-6;
// Below this squared length a tangent-frame vector cannot be normalised (lab 4's normal map).
const float KIT_MIN_TANGENT_LENGTH_SQUARED = 1e-12;
// Below this squared length a direction has no equirectangular angles: atan(0, 0) (lab 6).
const float KIT_MIN_DIRECTION_LENGTH_SQUARED = 1e-12;
// Largest finite value an RGBA16F target holds; lighting clamps to it so a
// specular peak cannot become +Inf (and then NaN in Reinhard's c/(c+1)).
const float KIT_HDR_MAX = 65504.0;
