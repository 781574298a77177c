#version 330 core
// Lab 5 - one direction of the separable Gaussian blur. See handouts/05-postprocess.md.
#include "uniforms.glsl"

in vec2 v_uv;
out vec4 out_color;

const float KIT_BLUR_WEIGHTS[5] = float[](0.227027, 0.1945946, 0.1216216, 0.054054, 0.016216);

void main() {
    // TODO(lab 5): sum the centre and 4 texels on each side along the direction
    //              given by u_horizontal, weighted by KIT_BLUR_WEIGHTS.
    //              One texel is 1.0 / u_resolution in uv units.
    out_color = vec4(texture(u_bloom, v_uv).rgb, 1.0);
}
