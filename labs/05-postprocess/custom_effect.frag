#version 330 core
// Lab 5 - your own effect (blur, water ripples, vignette, ...), applied to the
// tone-mapped image u_ldr. See handouts/05-postprocess.md.
#include "uniforms.glsl"

in vec2 v_uv;
out vec4 out_color;

void main() {
    vec3 color = texture(u_ldr, v_uv).rgb;
    if (u_postprocess_enabled && u_custom_enabled) {
        // TODO(lab 5): your effect. With the toggle off the image must pass
        //              through unchanged.
    }
    out_color = vec4(color, 1.0);
}
