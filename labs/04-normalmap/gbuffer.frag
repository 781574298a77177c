#version 330 core
// Lab 4 - normal mapping, fragment stage. Starts from lab 1's solution.
// See handouts/04-normalmap.md.
#include "geometry_uniforms.glsl"
#include "guards.glsl"  // KIT_MIN_TANGENT_LENGTH_SQUARED
#include "material_modes.glsl"  // kit_alpha_discard, kit_facing_normal

in vec3 v_world_position;
in vec3 v_world_normal;
in vec3 v_world_tangent;
in vec3 v_world_bitangent;
in vec4 v_texcoords;  // both UV slots; kit_base_color_uv(v_texcoords) and the like pick a texture's own
in vec4 v_color;  // linear rgba

layout(location = KIT_GBUF_POSITION) out vec4 out_position;
layout(location = KIT_GBUF_NORMAL) out vec4 out_normal;
layout(location = KIT_GBUF_ALBEDO) out vec4 out_albedo;
layout(location = KIT_GBUF_MATERIAL) out vec4 out_material;
layout(location = KIT_GBUF_EMISSION) out vec4 out_emission;

void main() {
    // glTF: factor * texel * COLOR_0, alpha included (it decides MASK coverage).
    vec4 base_color = u_base_color_factor * texture(u_base_color_texture, kit_base_color_uv(v_texcoords)) * v_color;
    kit_alpha_discard(base_color.a);  // MASK: below the cutoff, no surface here
    vec4 metallic_roughness = texture(u_metallic_roughness_texture, kit_metallic_roughness_uv(v_texcoords));
    float metallic = u_metallic_factor * metallic_roughness.b;
    float roughness = u_roughness_factor * metallic_roughness.g;
    vec3 emissive = u_emissive_factor * texture(u_emissive_texture, kit_emissive_uv(v_texcoords)).rgb;

    vec3 n = normalize(v_world_normal);
    if (u_has_normal_texture) {
        // TODO(lab 4): re-orthogonalise T and B against n (Gram-Schmidt), read
        //              the tangent-space normal (2 * texel - 1, the texel at
        //              kit_normal_uv(v_texcoords)) scaled by
        //              (u_normal_scale, u_normal_scale, 1), and take it to world
        //              space with the TBN matrix. Keep the result finite.
    }

    out_position = vec4(v_world_position, 1.0);
    out_normal = vec4(kit_facing_normal(n), 0.0);  // flipped on a double-sided back face
    out_albedo = base_color;  // .a: the base colour alpha
    out_material = vec4(metallic, roughness, 0.0, 1.0);  // .b unused, .a = coverage mask
    out_emission = vec4(emissive, 0.0);
}
