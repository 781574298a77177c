#version 330 core
// Lab 1 - geometry pass, fragment stage. Fill the G-buffer as laid out in
// gbuffer_layout.h (and the table in handouts/01-gbuffer.md).
#include "geometry_uniforms.glsl"

in vec3 v_world_position;
in vec3 v_world_normal;
in vec2 v_texcoord;

layout(location = KIT_GBUF_POSITION) out vec4 out_position;
layout(location = KIT_GBUF_NORMAL) out vec4 out_normal;
layout(location = KIT_GBUF_ALBEDO) out vec4 out_albedo;
layout(location = KIT_GBUF_MATERIAL) out vec4 out_material;

void main() {
    // TODO(lab 1): base colour = u_base_color_factor * the base colour texture.
    vec4 base_color = u_base_color_factor;
    // TODO(lab 1): metallic = u_metallic_factor * texel.b and
    //              roughness = u_roughness_factor * texel.g of u_metallic_roughness_texture.
    float metallic = 0.0;
    float roughness = 1.0;
    // TODO(lab 1): emission = the largest component of u_emissive_factor * emissive texel.
    float emission = 0.0;

    out_position = vec4(v_world_position, 1.0);
    // TODO(lab 1): the interpolated normal is no longer unit length.
    out_normal = vec4(v_world_normal, 0.0);
    out_albedo = vec4(base_color.rgb, 1.0);
    out_material = vec4(metallic, roughness, emission, 1.0);  // .a = coverage mask
}
