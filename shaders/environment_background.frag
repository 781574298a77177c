#version 330 core
// Lab 6: the environment behind the scene, where the G-buffer has no surface. Drawn
// after the lighting and IBL passes; covered pixels are left as they are.
#include "uniforms.glsl"
#include "environment.glsl"
#include "guards.glsl"

in vec2 v_uv;
out vec4 out_color;

void main() {
    if (texture(u_gbuffer_material, v_uv).a >= 0.5) discard;  // a surface is here
    // The view ray through this pixel: from its point on the near plane to its point on
    // the far plane (perspective and orthographic cameras alike).
    vec2 ndc = v_uv * 2.0 - 1.0;
    vec4 near_point = u_inv_view_projection * vec4(ndc, -1.0, 1.0);
    vec4 far_point = u_inv_view_projection * vec4(ndc, 1.0, 1.0);
    vec3 direction = far_point.xyz / far_point.w - near_point.xyz / near_point.w;
    out_color = vec4(min(kit_environment_radiance(direction), vec3(KIT_HDR_MAX)), 1.0);
}
