// Lab 2 - the Cook-Torrance BRDF (the lecture's). See handouts/02-lighting.md.
// Use the named guards from guards.glsl wherever a value can reach 0 in a denominator.
#include "guards.glsl"
#include "math.glsl"

// TODO(lab 2): Schlick's Fresnel, F = F0 + (1 - F0)(1 - v.h)^5.
vec3 fresnel_schlick(float v_dot_h, vec3 f0) {
    return f0;
}

// TODO(lab 2): GGX, D = a^2 / (pi ((n.h)^2 (a^2 - 1) + 1)^2).
float distribution_ggx(float n_dot_h, float alpha) {
    return 0.0;
}

// TODO(lab 2): G = min(1, 2(n.h)(n.v)/(v.h), 2(n.h)(n.l)/(v.h)). Cook-Torrance's G does not
// use the roughness; the signature has it for other G's (lab 6 calls this function too).
float microfacet_geometry(float n_dot_h, float n_dot_v, float n_dot_l, float v_dot_h, float roughness) {
    return 1.0;
}

// f = (1 - F)(1 - metallic) albedo/pi + F D G / (4 (n.l)(n.v))
vec3 cook_torrance(vec3 n, vec3 v, vec3 l, vec3 albedo, float metallic, float perceptual_roughness) {
    // TODO(lab 2): the half vector h, the floored dot products, alpha = roughness^2
    //              (after the KIT_MIN_ROUGHNESS floor), F0 mixed by metallic,
    //              then the diffuse and specular terms.
    return albedo / KIT_PI;  // Lambert only: no specular highlight yet
}
