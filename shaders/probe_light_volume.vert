#version 330 core
// Lab 7's pass probe (tools/grade/frames/pass_probes.cpp): light_volume.frag drawn alone as
// one light's volume would draw it, over every texel of the probe's target: the full-screen
// triangle, every fragment of light u_probe_light.
uniform int u_probe_light;
flat out int v_light;

void main() {
    vec2 corner = vec2((gl_VertexID << 1) & 2, gl_VertexID & 2);  // (0,0) (2,0) (0,2)
    v_light = u_probe_light;
    gl_Position = vec4(corner * 2.0 - 1.0, 0.0, 1.0);
}
