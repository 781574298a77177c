#version 330 core
// Lab 5 - composite the bloom onto the HDR image, then tone map.
// See handouts/05-postprocess.md.
#include "uniforms.glsl"
#include "tonemap.glsl"

in vec2 v_uv;
out vec4 out_color;

void main() {
    vec3 hdr = texture(u_hdr, v_uv).rgb;
    // TODO(lab 5): when u_postprocess_enabled, add the blurred bloom (u_bloom)
    //              before tone mapping.
    out_color = vec4(tonemap(hdr), 1.0);
}
