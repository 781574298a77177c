#version 330 core
// Lab 4 - normal mapping, vertex stage. Starts from lab 1's solution.
// See handouts/04-normalmap.md.
#include "geometry_uniforms.glsl"

layout(location = KIT_ATTR_POSITION) in vec3 a_position;
layout(location = KIT_ATTR_NORMAL) in vec3 a_normal;
layout(location = KIT_ATTR_TEXCOORD) in vec2 a_texcoord;
layout(location = KIT_ATTR_COLOR) in vec4 a_color;  // glTF COLOR_0 (white when the mesh has none)
layout(location = KIT_ATTR_TANGENT) in vec4 a_tangent;  // xyz tangent, w handedness

out vec3 v_world_position;
out vec3 v_world_normal;
out vec3 v_world_tangent;
out vec3 v_world_bitangent;
out vec2 v_texcoord;
out vec4 v_color;

void main() {
    vec4 world = u_model * vec4(a_position, 1.0);
    v_world_position = world.xyz;
    v_world_normal = u_normal_matrix * a_normal;
    // TODO(lab 4): the world-space tangent (which matrix takes a vector that
    //              lies in the surface?) and the bitangent B = cross(N, T) * w.
    v_world_tangent = vec3(0.0);
    v_world_bitangent = vec3(0.0);
    v_texcoord = a_texcoord;
    v_color = a_color;
    gl_Position = u_projection * u_view * world;
}
