#version 330 core
// Lab 2 - the lighting pass. See handouts/02-lighting.md.
#include "uniforms.glsl"
#include "lights.glsl"
#include "guards.glsl"
#include "brdf.glsl"
#include "attenuation.glsl"

in vec2 v_uv;
out vec4 out_color;

void main() {
    vec4 material = texture(u_gbuffer_material, v_uv);
    // TODO(lab 2): where the coverage mask (material.a) is 0, output u_clear_color.

    vec3 p = texture(u_gbuffer_position, v_uv).xyz;
    vec3 n = texture(u_gbuffer_normal, v_uv).xyz;
    vec3 albedo = texture(u_gbuffer_albedo, v_uv).rgb;

    vec3 radiance = vec3(0.0);
    // TODO(lab 2): L = L_e + sum over u_light_count lights (kit_light(i)) of
    //              cook_torrance(...) * light_radiance(light, p) * (n.l),
    //              with L_e = the emitted radiance in the G-buffer's emission
    //              attachment (u_gbuffer_emission). l points from p towards the
    //              light; a KIT_LIGHT_DIRECTIONAL light shines along light.direction.
    out_color = vec4(radiance + 0.1 * albedo, 1.0);  // placeholder so the scene is visible
}
