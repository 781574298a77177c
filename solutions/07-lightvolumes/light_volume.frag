#version 330 core
// Light volumes: one light's term at a pixel its volume covers, as lab 2's lighting pass
// computes it with lab 3's falloff. The framework adds it into the HDR target.
#include "uniforms.glsl"
#include "lights.glsl"
#include "guards.glsl"
#include "brdf.glsl"
#include "attenuation.glsl"

flat in int v_light;
out vec4 out_color;

void main() {
    // The fragment's pixel is the G-buffer's texel: read it exactly, without filtering.
    ivec2 pixel = ivec2(gl_FragCoord.xy);
    vec4 material = texelFetch(u_gbuffer_material, pixel, 0);
    // Alpha 0 everywhere: additive blending keeps the full-screen pass's alpha.
    out_color = vec4(0.0);
    if (material.a < 0.5) return;  // no surface: the background stays as it is
    Light light = kit_light(v_light);
    vec3 p = texelFetch(u_gbuffer_position, pixel, 0).xyz;
    vec3 to_light = light.position - p;
    // Outside the sphere the light adds less than its cut-off: nothing to shade.
    if (dot(to_light, to_light) > light.volume_radius * light.volume_radius) return;
    vec3 n = normalize(texelFetch(u_gbuffer_normal, pixel, 0).xyz);
    vec3 albedo = texelFetch(u_gbuffer_albedo, pixel, 0).rgb;
    vec3 v = normalize(u_camera_position - p);
    vec3 l = to_light * inversesqrt(max(dot(to_light, to_light), KIT_MIN_DISTANCE_SQUARED));
    float n_dot_l = dot(n, l);
    if (n_dot_l <= 0.0) return;  // light below the surface
    vec3 radiance = cook_torrance(n, v, l, albedo, material.r, material.g) * light_radiance(light, p) * n_dot_l;
    out_color = vec4(min(radiance, vec3(KIT_HDR_MAX)), 0.0);
}
