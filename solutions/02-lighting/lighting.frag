#version 330 core
// Lighting pass: reads the G-buffer and evaluates the reflectance equation for
// direct light, L = L_e + sum_i f(p, wo, wi) L_i (n.l), into the HDR target.
#include "uniforms.glsl"
#include "lights.glsl"
#include "guards.glsl"
#include "brdf.glsl"
#include "attenuation.glsl"

in vec2 v_uv;
out vec4 out_color;

void main() {
    vec4 material = texture(u_gbuffer_material, v_uv);
    if (material.a < 0.5) {  // mask 0: no surface here
        out_color = vec4(u_clear_color, 1.0);
        return;
    }
    vec3 p = texture(u_gbuffer_position, v_uv).xyz;
    vec3 n = normalize(texture(u_gbuffer_normal, v_uv).xyz);
    vec3 albedo = texture(u_gbuffer_albedo, v_uv).rgb;
    float metallic = material.r;
    float roughness = material.g;
    vec3 emission = texture(u_gbuffer_emission, v_uv).rgb;
    vec3 v = normalize(u_camera_position - p);

    vec3 radiance = emission;  // L_e
    for (int i = 0; i < u_light_count; ++i) {
        Light light = kit_light(i);
        vec3 l;
        if (light.type == KIT_LIGHT_DIRECTIONAL) {
            l = -light.direction;  // parallel rays: the same l at every p, whatever its node's position
        } else {
            vec3 to_light = light.position - p;
            // A light exactly at p has no direction: l = 0 makes n.l = 0 and it adds nothing.
            l = to_light * inversesqrt(max(dot(to_light, to_light), KIT_MIN_DISTANCE_SQUARED));
        }
        float n_dot_l = dot(n, l);
        if (n_dot_l <= 0.0) continue;  // light below the surface
        radiance += cook_torrance(n, v, l, albedo, metallic, roughness) * light_radiance(light, p) * n_dot_l;
    }
    out_color = vec4(min(radiance, vec3(KIT_HDR_MAX)), 1.0);
}
