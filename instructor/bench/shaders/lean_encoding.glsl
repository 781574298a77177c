// Encodings of the lean G-buffer (bench_layout.h): unit normals in two unorm
// channels, emitted radiance in one byte per channel.
#include "guards.glsl"

// Octahedral map (Cigolle et al. 2014, "A Survey of Efficient Representations for
// Independent Unit Vectors"): n is projected onto the octahedron |x|+|y|+|z| = 1 and
// the lower half is folded over the diagonals, so the square [-1,1]^2 holds the whole
// sphere with nearly uniform precision. Stored remapped to [0,1]^2 because unorm
// formats are colour-renderable in every GL 3.3 implementation (snorm ones need not be).
vec2 kit_sign_not_zero(vec2 v) {
    return vec2(v.x >= 0.0 ? 1.0 : -1.0, v.y >= 0.0 ? 1.0 : -1.0);
}

vec2 oct_encode(vec3 n) {
    vec2 p = n.xy / max(abs(n.x) + abs(n.y) + abs(n.z), KIT_MIN_DENOMINATOR);
    if (n.z < 0.0) p = (1.0 - abs(p.yx)) * kit_sign_not_zero(p);
    return p * 0.5 + 0.5;
}

vec3 oct_decode(vec2 stored) {
    vec2 f = stored * 2.0 - 1.0;
    vec3 n = vec3(f, 1.0 - abs(f.x) - abs(f.y));
    float fold = max(-n.z, 0.0);  // > 0 on the folded (lower) half
    n.xy -= fold * kit_sign_not_zero(n.xy);
    return normalize(n);
}

// Emitted radiance e >= 0, each channel stored as e / (1 + e) (the same mapping
// debug_view.frag shows): one byte keeps about 1 % relative precision for e between
// 0.3 and 3 and never overflows. The decode's denominator is floored at half a code
// step, so the top code (255) decodes to 510 instead of +Inf.
const float KIT_LEAN_EMISSION_FLOOR = 0.5 / 255.0;

vec3 emission_encode(vec3 e) {
    return e / (1.0 + max(e, 0.0));
}

vec3 emission_decode(vec3 stored) {
    return stored / max(1.0 - stored, KIT_LEAN_EMISSION_FLOOR);
}
