#version 330 core
// Maps one G-buffer attachment for display: vectors as (v + 1) / 2, depth
// linearised, the material as (metallic, roughness, 0), the emitted radiance
// as e/(1+e) per channel (Reinhard: HDR values above 1 stay distinguishable).
#include "uniforms.glsl"

uniform int u_view_mode;  // 0 position, 1 normal, 2 albedo, 3 material, 4 depth, 5 emission
uniform vec3 u_position_center;
uniform vec3 u_position_half_extent;
uniform float u_depth_display_far;

in vec2 v_uv;
out vec4 out_color;

float linear_depth(float window_depth) {
    float n = u_camera_near_far.x, f = u_camera_near_far.y;
    float ndc = window_depth * 2.0 - 1.0;
    return 2.0 * n * f / (f + n - ndc * (f - n));
}

void main() {
    float mask = texture(u_gbuffer_material, v_uv).a;
    vec3 c;
    if (u_view_mode == 0) {
        vec3 p = texture(u_gbuffer_position, v_uv).xyz;
        c = ((p - u_position_center) / u_position_half_extent + 1.0) * 0.5;
    } else if (u_view_mode == 1) {
        c = (texture(u_gbuffer_normal, v_uv).xyz + 1.0) * 0.5;
    } else if (u_view_mode == 2) {
        c = texture(u_gbuffer_albedo, v_uv).rgb;
    } else if (u_view_mode == 3) {
        vec3 m = texture(u_gbuffer_material, v_uv).rgb;
        c = vec3(m.r, m.g, 0.0);
    } else if (u_view_mode == 5) {
        vec3 e = max(texture(u_gbuffer_emission, v_uv).rgb, 0.0);
        c = e / (1.0 + e);
    } else {
        float z = linear_depth(texture(u_gbuffer_depth, v_uv).r);
        float n = u_camera_near_far.x;
        c = vec3(clamp((z - n) / max(u_depth_display_far - n, 1e-6), 0.0, 1.0));
    }
    out_color = vec4(mask > 0.5 || u_view_mode == 4 ? c : vec3(0.0), 1.0);
}
