// Cook-Torrance BRDF (the lecture's). Every guard is a named constant in guards.glsl.
#include "guards.glsl"
#include "math.glsl"

// Schlick's Fresnel: F = F0 + (1 - F0)(1 - v.h)^5.
vec3 fresnel_schlick(float v_dot_h, vec3 f0) {
    // clamp: rounding can leave v.h a hair above 1. The fifth power by two squarings:
    // pow() is exp2(5 log2 m), which in a loop over 32 lights cost llvmpipe's lighting
    // pass about a tenth of its time (handouts/02-lighting.md, "Speed").
    float m = clamp(1.0 - v_dot_h, 0.0, 1.0);
    float m2 = m * m;
    return f0 + (1.0 - f0) * (m2 * m2 * m);
}

// GGX / Trowbridge-Reitz: D = a^2 / (pi ((n.h)^2 (a^2 - 1) + 1)^2), a = roughness^2.
float distribution_ggx(float n_dot_h, float alpha) {
    float alpha2 = alpha * alpha;
    float d = n_dot_h * n_dot_h * (alpha2 - 1.0) + 1.0;
    return alpha2 / max(KIT_PI * d * d, KIT_MIN_GGX_DENOMINATOR);
}

// The microfacet geometric function, Cook-Torrance's (the lecture's):
// G = min(1, 2(n.h)(n.v)/(v.h), 2(n.h)(n.l)/(v.h)). Its arguments are every one a G may need
// (Smith's uses the roughness), so that a course changing G changes this body only: lab 6's
// BRDF table calls this function too.
float microfacet_geometry(float n_dot_h, float n_dot_v, float n_dot_l, float v_dot_h, float roughness) {
    return min(1.0, min(2.0 * n_dot_h * n_dot_v / v_dot_h, 2.0 * n_dot_h * n_dot_l / v_dot_h));
}

// f(p, wo, wi) = (1 - F)(1 - metallic) c/pi + F D G / (4 (n.l)(n.v)); n, v, l are unit vectors.
vec3 cook_torrance(vec3 n, vec3 v, vec3 l, vec3 albedo, float metallic, float perceptual_roughness) {
    vec3 half_sum = v + l;
    vec3 h = half_sum * inversesqrt(max(dot(half_sum, half_sum), KIT_MIN_DENOMINATOR));
    float n_dot_v = max(dot(n, v), KIT_MIN_N_DOT_V);
    float n_dot_l = max(dot(n, l), KIT_MIN_N_DOT_L);
    float n_dot_h = clamp(dot(n, h), 0.0, 1.0);
    float v_dot_h = max(dot(v, h), KIT_MIN_V_DOT_H);
    float roughness = max(perceptual_roughness, KIT_MIN_ROUGHNESS);
    float alpha = roughness * roughness;  // glTF convention: alpha = perceptual roughness squared

    vec3 f0 = mix(vec3(0.04), albedo, metallic);  // (1 - metallic) 0.04 + metallic albedo
    vec3 F = fresnel_schlick(v_dot_h, f0);
    float D = distribution_ggx(n_dot_h, alpha);
    float G = microfacet_geometry(n_dot_h, n_dot_v, n_dot_l, v_dot_h, roughness);

    vec3 diffuse = (1.0 - F) * (1.0 - metallic) * albedo / KIT_PI;
    vec3 specular = F * D * G / max(4.0 * n_dot_l * n_dot_v, KIT_MIN_DENOMINATOR);
    return diffuse + specular;
}
