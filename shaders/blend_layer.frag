#version 330 core
// The forward pass's over operator (common/render/forward_pass.h): one BLEND draw was
// drawn into a layer G-buffer and lit by the stage's lighting pass into u_hdr;
// this lays it over the scene's HDR target, which GL blends as
// a * L_layer + (1 - a) * L_behind (glBlendFunc SRC_ALPHA, ONE_MINUS_SRC_ALPHA),
// a = the base colour alpha the geometry pass kept in albedo.a.
#include "uniforms.glsl"

in vec2 v_uv;
out vec4 out_color;

void main() {
    if (texture(u_gbuffer_material, v_uv).a < 0.5) discard;  // mask 0: the layer has no surface here
    float alpha = clamp(texture(u_gbuffer_albedo, v_uv).a, 0.0, 1.0);
    out_color = vec4(texture(u_hdr, v_uv).rgb, alpha);
}
