#version 330 core
// Lab 1 - geometry pass, fragment stage. Fill the G-buffer as laid out in
// gbuffer_layout.h (and the table in handouts/01-gbuffer.md).
#include "geometry_uniforms.glsl"
#include "material_modes.glsl"  // kit_alpha_discard, kit_facing_normal

in vec3 v_world_position;
in vec3 v_world_normal;
in vec4 v_texcoords;  // both UV slots; kit_base_color_uv(v_texcoords) and the like pick a texture's own
in vec4 v_color;  // linear rgba

layout(location = KIT_GBUF_POSITION) out vec4 out_position;
layout(location = KIT_GBUF_NORMAL) out vec4 out_normal;
layout(location = KIT_GBUF_ALBEDO) out vec4 out_albedo;
layout(location = KIT_GBUF_MATERIAL) out vec4 out_material;
layout(location = KIT_GBUF_EMISSION) out vec4 out_emission;

void main() {
    // Each texture is sampled at its own UV: kit_base_color_uv(v_texcoords) for the
    // base colour texture, kit_metallic_roughness_uv and kit_emissive_uv for the others.
    // TODO(lab 1): base colour = u_base_color_factor * the base colour texture
    //              * the vertex colour, alpha included.
    vec4 base_color = u_base_color_factor;
    kit_alpha_discard(base_color.a);  // MASK: below the cutoff, no surface here
    // TODO(lab 1): metallic = u_metallic_factor * texel.b and
    //              roughness = u_roughness_factor * texel.g of u_metallic_roughness_texture.
    float metallic = 0.0;
    float roughness = 1.0;
    // TODO(lab 1): emission = u_emissive_factor * the emissive texture's texel.
    vec3 emission = vec3(0.0);

    out_position = vec4(v_world_position, 1.0);
    // TODO(lab 1): the interpolated normal is no longer unit length.
    out_normal = vec4(kit_facing_normal(v_world_normal), 0.0);  // flipped on a double-sided back face
    out_albedo = base_color;  // .a: the base colour alpha
    out_material = vec4(metallic, roughness, 0.0, 1.0);  // .b unused, .a = coverage mask
    out_emission = vec4(emission, 0.0);
}
