#version 330 core
// A light marker shows its light's colour, unlit, into the HDR target.
uniform vec3 u_marker_radiance;  // linear HDR
out vec4 out_color;

void main() {
    out_color = vec4(u_marker_radiance, 1.0);
}
