#version 330 core
// Lab 1 - geometry pass, vertex stage. See handouts/01-gbuffer.md.
#include "geometry_uniforms.glsl"

layout(location = KIT_ATTR_POSITION) in vec3 a_position;
layout(location = KIT_ATTR_NORMAL) in vec3 a_normal;
layout(location = KIT_ATTR_TEXCOORD) in vec2 a_texcoord0;   // UV slot 0
layout(location = KIT_ATTR_TEXCOORD1) in vec2 a_texcoord1;  // UV slot 1 (zero unless a texture reads a second UV set)
layout(location = KIT_ATTR_COLOR) in vec4 a_color;  // glTF COLOR_0 (white when the mesh has none)

out vec3 v_world_position;
out vec3 v_world_normal;
out vec4 v_texcoords;  // .xy UV slot 0, .zw UV slot 1: each texture picks its own (kit_texture_uv)
out vec4 v_color;

void main() {
    vec4 world = u_model * vec4(a_position, 1.0);
    // TODO(lab 1): pass the world-space position to the fragment stage.
    v_world_position = vec3(0.0);
    // TODO(lab 1): bring the normal to world space with the normal matrix
    //              (u_normal_matrix), not with u_model. Why? See the handout.
    v_world_normal = a_normal;
    v_texcoords = vec4(a_texcoord0, a_texcoord1);
    v_color = a_color;
    gl_Position = u_projection * u_view * world;
}
