#version 330 core
// Lab 6 - the BRDF table of the split sum. See handouts/06-ibl.md.
#include "environment.glsl"
#include "sampling.glsl"
#include "guards.glsl"
#include "brdf.glsl"

in vec2 v_uv;
out vec4 out_color;

uniform int u_sample_count;

void main() {
    // This texel's grid point: n.v and perceptual roughness, each in [0, 1].
    float n_dot_v = kit_brdf_lut_grid_value(v_uv.x);
    float roughness = kit_brdf_lut_grid_value(v_uv.y);

    // TODO(lab 6): with n = +Z and v = (sqrt(1 - (n.v)^2), 0, n.v), estimate over
    //              u_sample_count Hammersley points (kit_hammersley):
    //              A = integral of (1 - Fc) f_spec (n.l), B = integral of Fc f_spec (n.l),
    //              with f_spec = D G / (4 (n.l)(n.v)) of lab 2 (distribution_ggx,
    //              microfacet_geometry) and Fc = (1 - v.h)^5,
    //              by GGX importance sampling (kit_sample_ggx_half_vector, l = reflect(-v, h));
    //              C = 1/pi integral of (1 - Fc)(n.l), by cosine sampling (kit_sample_cosine).
    //              Mind n.v = 0 and roughness 0 (guards.glsl).
    out_color = vec4(1.0, 0.0, 1.0, 1.0);  // placeholder: F0 for the specular, full diffuse
}
