#version 330 core
// Free-choice effect: water ripples. Concentric waves around the image centre
// displace the lookup; with the toggle off the image passes through unchanged.
#include "uniforms.glsl"

in vec2 v_uv;
out vec4 out_color;

const float RIPPLE_FREQUENCY = 60.0;  // radians per unit of uv distance
const float RIPPLE_SPEED = 4.0;       // radians per second
const float RIPPLE_AMPLITUDE = 0.004; // uv units

void main() {
    vec2 uv = v_uv;
    if (u_postprocess_enabled && u_custom_enabled) {
        vec2 from_center = v_uv - 0.5;
        float r = length(from_center);
        vec2 direction = r > 1e-6 ? from_center / r : vec2(0.0);
        uv += direction * RIPPLE_AMPLITUDE * sin(RIPPLE_FREQUENCY * r - RIPPLE_SPEED * u_time);
    }
    out_color = vec4(texture(u_ldr, uv).rgb, 1.0);
}
