#version 330 core
// Bloom, step 3: add the blurred bright pass to the HDR image before tone
// mapping. With the toggle off this is exactly the display pass of stage 4.
#include "uniforms.glsl"
#include "tonemap.glsl"

in vec2 v_uv;
out vec4 out_color;

void main() {
    vec3 hdr = texture(u_hdr, v_uv).rgb;
    if (u_postprocess_enabled) hdr += texture(u_bloom, v_uv).rgb;
    out_color = vec4(tonemap(hdr), 1.0);
}
