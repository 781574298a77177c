#version 330 core
// Lab 6 - one level of the prefiltered radiance map. See handouts/06-ibl.md.
#include "environment.glsl"
#include "sampling.glsl"
#include "guards.glsl"
#include "brdf.glsl"

in vec2 v_uv;
out vec4 out_color;

uniform float u_roughness;     // this level's perceptual roughness
uniform int u_sample_count;

void main() {
    vec3 r = kit_equirect_direction(v_uv);  // n = v = r (the split sum's assumption)

    // TODO(lab 6): average the environment (u_environment) over GGX's lobe of
    //              u_roughness around r: u_sample_count half vectors h
    //              (kit_sample_ggx_half_vector, turned around r with kit_around),
    //              l = reflect(-v, h), each sample weighted by n.l. Floor the roughness
    //              at KIT_MIN_ROUGHNESS as lab 2 does (level 0 is a mirror). Read each
    //              sample from the mip level whose texels cover the solid angle the
    //              sample stands for, 1 / (N pdf), plus one level (the handout says
    //              why), so a small bright source does not become fireflies.
    out_color = vec4(kit_environment_radiance(r), 1.0);  // placeholder: no filtering
}
