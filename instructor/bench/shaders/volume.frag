#version 330 core
// Light volumes: one light's term at the pixels its volume covers, added into the
// HDR target by blending (ONE, ONE). Only back faces are drawn (front faces culled),
// so every covered pixel is shaded once, also when the camera is inside the volume
// (stability case 7). Surfaces outside the sphere get nothing, so the result does
// not depend on how the volume projects.
#include "shade.glsl"
#include "light_bounds.glsl"

flat in Light v_light;
flat in float v_radius;
out vec4 out_color;

void main() {
    ivec2 pixel = ivec2(gl_FragCoord.xy);
    Light light = v_light;
    // Most covered pixels are outside the sphere: test with the position alone first.
    vec3 position;
    bool covered = read_position(pixel, position);
    vec3 from_light = position - light_position(light);
    if (!covered || dot(from_light, from_light) > v_radius * v_radius) discard;
    Surface s = read_surface(pixel);
    // Alpha 0: the base pass's alpha of 1 stays 1 under additive blending.
    out_color = vec4(u_count_lights ? vec3(1.0) : min(shade_light(s, view_direction(s), light), vec3(KIT_HDR_MAX)), 0.0);
}
