#version 330 core
// Full-screen lighting, every light at every pixel: the labs' method
// (solutions/02-lighting/lighting.frag) for any bench G-buffer layout. With
// u_light_count = 0 it writes only emission and the clear colour: the base the
// light volumes add onto.
#include "shade.glsl"

in vec2 v_uv;
out vec4 out_color;

void main() {
    Surface s = read_surface(ivec2(gl_FragCoord.xy));
    out_color = vec4(s.covered ? shade_all(s, u_light_count) : u_clear_color, 1.0);
}
