#version 330 core
// Lab 5 - bloom bright pass. See handouts/05-postprocess.md.
#include "uniforms.glsl"
#include "guards.glsl"
#include "math.glsl"

in vec2 v_uv;
out vec4 out_color;

void main() {
    vec3 c = texture(u_hdr, v_uv).rgb;
    // TODO(lab 5): keep c where its luminance (KIT_LUMINANCE) exceeds
    //              u_bloom_threshold, else black. A NaN or Inf must not get through.
    out_color = vec4(0.0, 0.0, 0.0, 1.0);
}
