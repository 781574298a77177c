// Sample points for lab 6's integrals (handouts/06-ibl.md, "Estimating an integral").
#include "math.glsl"

// The i-th of n Hammersley points in [0,1)^2: (i/n, the radical inverse of i in base
// 2). Evenly spread, so a few hundred samples converge far faster than random ones.
// (bitfieldReverse would do the bit reversal in one call, but it needs GLSL 4.00.)
vec2 kit_hammersley(int i, int n) {
    uint bits = uint(i);
    bits = (bits << 16u) | (bits >> 16u);
    bits = ((bits & 0x55555555u) << 1u) | ((bits & 0xAAAAAAAAu) >> 1u);
    bits = ((bits & 0x33333333u) << 2u) | ((bits & 0xCCCCCCCCu) >> 2u);
    bits = ((bits & 0x0F0F0F0Fu) << 4u) | ((bits & 0xF0F0F0F0u) >> 4u);
    bits = ((bits & 0x00FF00FFu) << 8u) | ((bits & 0xFF00FF00u) >> 8u);
    return vec2(float(i) / float(n), float(bits) * 2.3283064365386963e-10);  // / 2^32
}

// A half vector h around +Z with density D(h)(n.h) (GGX with alpha = roughness^2), from
// a point xi of [0,1)^2 by inverting the distribution of n.h:
// cos^2 theta_h = (1 - xi.x) / (1 + (alpha^2 - 1) xi.x), phi = 2 pi xi.y.
vec3 kit_sample_ggx_half_vector(vec2 xi, float alpha) {
    float alpha_squared = alpha * alpha;
    float cos_theta = sqrt((1.0 - xi.x) / (1.0 + (alpha_squared - 1.0) * xi.x));
    float sin_theta = sqrt(max(1.0 - cos_theta * cos_theta, 0.0));
    float phi = 2.0 * KIT_PI * xi.y;
    return vec3(sin_theta * cos(phi), sin_theta * sin(phi), cos_theta);
}

// A direction around +Z with density cos(theta) / pi (Malley: a uniform point of the
// unit disc lifted onto the hemisphere).
vec3 kit_sample_cosine(vec2 xi) {
    float radius = sqrt(xi.x);
    float phi = 2.0 * KIT_PI * xi.y;
    return vec3(radius * cos(phi), radius * sin(phi), sqrt(max(1.0 - xi.x, 0.0)));
}

// `v` given around +Z, turned so that +Z becomes the unit vector n (any tangent frame:
// the samples are symmetric about their axis).
vec3 kit_around(vec3 n, vec3 v) {
    vec3 helper = abs(n.z) < 0.999 ? vec3(0.0, 0.0, 1.0) : vec3(1.0, 0.0, 0.0);
    vec3 tangent = normalize(cross(helper, n));
    vec3 bitangent = cross(n, tangent);
    return tangent * v.x + bitangent * v.y + n * v.z;
}
