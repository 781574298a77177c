#version 330 core
// Lab 6, the BRDF table: for each (n.v, roughness) of the grid, the three integrals the
// split sum needs, over a uniform white environment (handouts/06-ibl.md):
//   A = integral of (1 - Fc) f_spec (n.l) dl,  B = integral of Fc f_spec (n.l) dl,
//   C = 1/pi integral of (1 - Fc) (n.l) dl,
// with f_spec = D G / (4 (n.l)(n.v)) of lab 2 and Fc = (1 - v.h)^5, so that
// F0 A + B is the specular and (1 - F0) C the diffuse part's Fresnel weight.
#include "environment.glsl"
#include "sampling.glsl"
#include "guards.glsl"
#include "brdf.glsl"

in vec2 v_uv;
out vec4 out_color;

uniform int u_sample_count;

void main() {
    // n.v = 0 gives v.h = 0 for the half vectors near the horizon and divides by n.v:
    // the row at n.v = 0 is evaluated at the floor instead.
    float n_dot_v = max(kit_brdf_lut_grid_value(v_uv.x), KIT_MIN_N_DOT_V);
    float roughness = max(kit_brdf_lut_grid_value(v_uv.y), KIT_MIN_ROUGHNESS);
    float alpha = roughness * roughness;
    vec3 v = vec3(sqrt(1.0 - n_dot_v * n_dot_v), 0.0, n_dot_v);  // n = +Z

    float a = 0.0, b = 0.0, c = 0.0;
    for (int i = 0; i < u_sample_count; ++i) {
        vec2 xi = kit_hammersley(i, u_sample_count);
        // Specular: l = reflect(-v, h), h drawn with density D (n.h), so l has density
        // D (n.h) / (4 v.h) and f_spec (n.l) / pdf = G (v.h) / ((n.h)(n.v)).
        vec3 h = kit_sample_ggx_half_vector(xi, alpha);
        vec3 l = reflect(-v, h);
        float n_dot_l = l.z;
        if (n_dot_l > 0.0) {
            float n_dot_h = h.z;
            float v_dot_h = max(dot(v, h), KIT_MIN_V_DOT_H);
            float g = microfacet_geometry(n_dot_h, n_dot_v, n_dot_l, v_dot_h, roughness);
            float weight = g * v_dot_h / max(n_dot_h * n_dot_v, KIT_MIN_DENOMINATOR);
            float fc = pow(1.0 - v_dot_h, 5.0);
            a += (1.0 - fc) * weight;
            b += fc * weight;
        }
        // Diffuse: l drawn with density (n.l) / pi, so (1/pi)(1 - Fc)(n.l) / pdf = 1 - Fc.
        vec3 l_diffuse = kit_sample_cosine(xi);
        vec3 half_sum = v + l_diffuse;
        vec3 h_diffuse = half_sum * inversesqrt(max(dot(half_sum, half_sum), KIT_MIN_DENOMINATOR));
        c += 1.0 - pow(1.0 - clamp(dot(v, h_diffuse), 0.0, 1.0), 5.0);
    }
    out_color = vec4(vec3(a, b, c) / float(u_sample_count), 1.0);
}
