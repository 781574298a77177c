#version 330 core
// Lab 6, the irradiance map: for each normal n, E(n) = integral of L(l) max(n.l, 0) dl,
// summed over the texels of a small level of the environment, each weighted by its
// solid angle (handouts/06-ibl.md). The sum is exact for the level it reads; E is so
// smooth that a 128 x 64 level loses little even under the kit's sun (test_ibl).
#include "environment.glsl"

in vec2 v_uv;
out vec4 out_color;

uniform int u_source_level;  // the environment's level to sum over

void main() {
    vec3 n = kit_equirect_direction(v_uv);
    ivec2 size = textureSize(u_environment, u_source_level);
    vec3 irradiance = vec3(0.0);
    for (int y = 0; y < size.y; ++y) {
        float solid_angle = kit_equirect_texel_solid_angle(y, size);
        for (int x = 0; x < size.x; ++x) {
            vec3 l = kit_equirect_direction((vec2(x, y) + 0.5) / vec2(size));
            float n_dot_l = dot(n, l);
            if (n_dot_l <= 0.0) continue;
            irradiance += texelFetch(u_environment, ivec2(x, y), u_source_level).rgb * n_dot_l * solid_angle;
        }
    }
    out_color = vec4(irradiance, 1.0);
}
