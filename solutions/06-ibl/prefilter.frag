#version 330 core
// Lab 6, one level of the prefiltered radiance map: for each direction r, the
// environment averaged over GGX's lobe of this level's roughness, with Karis' split-sum
// assumption n = v = r (handouts/06-ibl.md):
//   P(r) = integral L(l) D(h) (n.l) dl / integral D(h) (n.l) dl.
#include "environment.glsl"
#include "sampling.glsl"
#include "guards.glsl"
#include "brdf.glsl"

in vec2 v_uv;
out vec4 out_color;

uniform float u_roughness;     // this level's perceptual roughness
uniform int u_sample_count;

void main() {
    vec3 n = kit_equirect_direction(v_uv);
    vec3 v = n;
    float alpha = max(u_roughness, KIT_MIN_ROUGHNESS) * max(u_roughness, KIT_MIN_ROUGHNESS);
    // The solid angle one texel of level 0 covers on average.
    ivec2 size = textureSize(u_environment, 0);
    float texel_solid_angle = 4.0 * KIT_PI / float(size.x * size.y);

    vec3 sum = vec3(0.0);
    float weight = 0.0;
    for (int i = 0; i < u_sample_count; ++i) {
        vec3 h = kit_around(n, kit_sample_ggx_half_vector(kit_hammersley(i, u_sample_count), alpha));
        vec3 l = reflect(-v, h);
        float n_dot_l = dot(n, l);
        if (n_dot_l <= 0.0) continue;
        // Filtered importance sampling: a sample stands for the solid angle 1 / (N pdf);
        // read the mip level whose texels cover that much, so a small bright source is
        // averaged into the sample instead of hit by a few samples (fireflies).
        float n_dot_h = clamp(dot(n, h), 0.0, 1.0);
        float pdf = distribution_ggx(n_dot_h, alpha) / 4.0;  // D (n.h) / (4 v.h), v.h = n.h
        float sample_solid_angle = 1.0 / (float(u_sample_count) * max(pdf, KIT_MIN_DENOMINATOR));
        float level = max(0.5 * log2(sample_solid_angle / texel_solid_angle) + 1.0, 0.0);
        sum += textureLod(u_environment, kit_equirect_uv(l), level).rgb * n_dot_l;
        weight += n_dot_l;
    }
    out_color = vec4(sum / max(weight, KIT_MIN_DENOMINATOR), 1.0);
}
