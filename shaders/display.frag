#version 330 core
// Shows the HDR lighting result through the stage's tonemap.glsl.
#include "uniforms.glsl"
#include "tonemap.glsl"

in vec2 v_uv;
out vec4 out_color;

void main() {
    out_color = vec4(tonemap(texture(u_hdr, v_uv).rgb), 1.0);
}
