#version 330 core
// Lab 6, the image-based lighting pass: the environment's light reflected towards the
// camera, by the split sum (handouts/06-ibl.md). Added to the lighting pass's result
// (direct lights and L_e) in the HDR target.
#include "uniforms.glsl"
#include "environment.glsl"
#include "guards.glsl"
#include "brdf.glsl"

in vec2 v_uv;
out vec4 out_color;

void main() {
    vec4 material = texture(u_gbuffer_material, v_uv);
    if (material.a < 0.5) {  // no surface: the framework draws the environment here
        out_color = vec4(0.0);
        return;
    }
    vec3 p = texture(u_gbuffer_position, v_uv).xyz;
    vec3 n = normalize(texture(u_gbuffer_normal, v_uv).xyz);
    vec3 albedo = texture(u_gbuffer_albedo, v_uv).rgb;
    float metallic = material.r;
    float roughness = material.g;
    vec3 v = normalize(u_camera_position - p);
    float n_dot_v = max(dot(n, v), KIT_MIN_N_DOT_V);

    vec3 f0 = mix(vec3(0.04), albedo, metallic);
    vec3 table = kit_brdf_lut(n_dot_v, roughness);  // (A, B, C)
    vec3 specular = (f0 * table.x + table.y) * kit_prefiltered_radiance(reflect(-v, n), roughness);
    vec3 diffuse = (1.0 - metallic) * albedo * (1.0 - f0) * table.z * kit_irradiance(n) / KIT_PI;
    out_color = vec4(min(specular + diffuse, vec3(KIT_HDR_MAX)), 1.0);
}
