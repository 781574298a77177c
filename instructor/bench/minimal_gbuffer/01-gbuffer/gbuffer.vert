#version 330 core
// The minimal geometry pass (docs/performance.md, "The geometry pass's material path"):
// one UV set, no texture transform or vertex colour, for timing the kit's default one
// against (kit-render --shaders instructor/bench/minimal_gbuffer/01-gbuffer). It draws
// a scene that uses none of those as the labs' solution does.
#include "geometry_uniforms.glsl"

layout(location = KIT_ATTR_POSITION) in vec3 a_position;
layout(location = KIT_ATTR_NORMAL) in vec3 a_normal;
layout(location = KIT_ATTR_TEXCOORD) in vec2 a_texcoord0;

out vec3 v_world_position;
out vec3 v_world_normal;
out vec2 v_uv;

void main() {
    vec4 world = u_model * vec4(a_position, 1.0);
    v_world_position = world.xyz;
    v_world_normal = u_normal_matrix * a_normal;
    v_uv = a_texcoord0;
    gl_Position = u_projection * u_view * world;
}
