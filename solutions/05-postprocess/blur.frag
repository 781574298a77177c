#version 330 core
// Bloom, step 2: one direction of a separable 9-tap Gaussian blur. The
// framework alternates u_horizontal and ping-pongs two targets.
#include "uniforms.glsl"

in vec2 v_uv;
out vec4 out_color;

// Fixed weights (handouts/05-postprocess.md): centre, then offsets 1..4; they sum to 1.
const float KIT_BLUR_WEIGHTS[5] = float[](0.227027, 0.1945946, 0.1216216, 0.054054, 0.016216);

void main() {
    vec2 step_uv = (u_horizontal ? vec2(1.0, 0.0) : vec2(0.0, 1.0)) / u_resolution;
    vec3 sum = texture(u_bloom, v_uv).rgb * KIT_BLUR_WEIGHTS[0];
    for (int i = 1; i < 5; ++i) {
        sum += texture(u_bloom, v_uv + step_uv * float(i)).rgb * KIT_BLUR_WEIGHTS[i];
        sum += texture(u_bloom, v_uv - step_uv * float(i)).rgb * KIT_BLUR_WEIGHTS[i];
    }
    out_color = vec4(sum, 1.0);
}
