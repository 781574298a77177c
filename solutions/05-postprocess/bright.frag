#version 330 core
// Bloom, step 1: keep the HDR pixels brighter than the threshold.
#include "uniforms.glsl"
#include "guards.glsl"
#include "math.glsl"

in vec2 v_uv;
out vec4 out_color;

void main() {
    vec3 c = texture(u_hdr, v_uv).rgb;
    // A NaN or Inf here would be smeared by every blur pass over the whole
    // kernel footprint: drop it (it contributes no bloom).
    if (any(isnan(c)) || any(isinf(c))) c = vec3(0.0);
    c = min(c, vec3(KIT_HDR_MAX));
    float luminance = dot(c, KIT_LUMINANCE);
    out_color = vec4(luminance > u_bloom_threshold ? c : vec3(0.0), 1.0);
}
