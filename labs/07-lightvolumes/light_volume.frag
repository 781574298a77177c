#version 330 core
// Light volumes: one light's term at a pixel its volume covers, as lab 2's lighting pass
// computes it with lab 3's falloff. The framework adds it into the HDR target.
#include "uniforms.glsl"
#include "lights.glsl"
#include "guards.glsl"
#include "brdf.glsl"
#include "attenuation.glsl"

flat in int v_light;
out vec4 out_color;

void main() {
    // TODO: the G-buffer texel under this fragment (gl_FragCoord is in pixels), the
    // surface there, and light v_light's term at it: cook_torrance, light_radiance and
    // n.l, as your lighting pass adds it. Write alpha 0 (the full-screen pass's alpha stays).
    out_color = vec4(0.0);
}
