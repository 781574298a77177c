#version 330 core
// Lab 4 - normal mapping, vertex stage. Starts from lab 1's solution.
// See handouts/04-normalmap.md.
#include "geometry_uniforms.glsl"

layout(location = KIT_ATTR_POSITION) in vec3 a_position;
layout(location = KIT_ATTR_NORMAL) in vec3 a_normal;
layout(location = KIT_ATTR_TEXCOORD) in vec2 a_texcoord0;   // UV slot 0
layout(location = KIT_ATTR_TEXCOORD1) in vec2 a_texcoord1;  // UV slot 1 (zero unless a texture reads a second UV set)
layout(location = KIT_ATTR_COLOR) in vec4 a_color;  // glTF COLOR_0 (white when the mesh has none)
layout(location = KIT_ATTR_TANGENT) in vec4 a_tangent;  // xyz tangent, w handedness

out vec3 v_world_position;
out vec3 v_world_normal;
out vec3 v_world_tangent;
out vec3 v_world_bitangent;
out vec4 v_texcoords;  // .xy UV slot 0, .zw UV slot 1: each texture picks its own (kit_texture_uv)
out vec4 v_color;

void main() {
    vec4 world = u_model * vec4(a_position, 1.0);
    v_world_position = world.xyz;
    v_world_normal = u_normal_matrix * a_normal;
    // TODO(lab 4): the world-space tangent (which matrix takes a vector that
    //              lies in the surface?) and the bitangent B = cross(N, T) * w.
    v_world_tangent = vec3(0.0);
    v_world_bitangent = vec3(0.0);
    v_texcoords = vec4(a_texcoord0, a_texcoord1);
    v_color = a_color;
    gl_Position = u_projection * u_view * world;
}
