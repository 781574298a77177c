#version 330 core
// Lab 6 - the irradiance map. See handouts/06-ibl.md.
#include "environment.glsl"

in vec2 v_uv;
out vec4 out_color;

uniform int u_source_level;  // the environment's level to sum over

void main() {
    vec3 n = kit_equirect_direction(v_uv);

    // TODO(lab 6): E(n) = integral of L(l) max(n.l, 0) over all directions l, as a sum
    //              over the texels of level u_source_level of u_environment (texelFetch),
    //              each weighted by its solid angle (kit_equirect_texel_solid_angle),
    //              in the direction of the texel's centre, (x + 0.5, y + 0.5) / size.
    out_color = vec4(KIT_PI * kit_environment_radiance(n), 1.0);  // placeholder: one direction
}
