#version 330 core
// The minimal geometry pass's fragment stage: the G-buffer the labs' solution writes,
// every texture sampled at UV slot 0 untransformed, no vertex colour, no MASK test.
#include "geometry_uniforms.glsl"
#include "material_modes.glsl"  // kit_facing_normal

in vec3 v_world_position;
in vec3 v_world_normal;
in vec2 v_uv;

layout(location = KIT_GBUF_POSITION) out vec4 out_position;
layout(location = KIT_GBUF_NORMAL) out vec4 out_normal;
layout(location = KIT_GBUF_ALBEDO) out vec4 out_albedo;
layout(location = KIT_GBUF_MATERIAL) out vec4 out_material;
layout(location = KIT_GBUF_EMISSION) out vec4 out_emission;

void main() {
    vec4 base_color = u_base_color_factor * texture(u_base_color_texture, v_uv);
    vec4 metallic_roughness = texture(u_metallic_roughness_texture, v_uv);
    vec3 emissive = u_emissive_factor * texture(u_emissive_texture, v_uv).rgb;
    out_position = vec4(v_world_position, 1.0);
    out_normal = vec4(kit_facing_normal(normalize(v_world_normal)), 0.0);
    out_albedo = base_color;
    out_material = vec4(u_metallic_factor * metallic_roughness.b, u_roughness_factor * metallic_roughness.g, 0.0, 1.0);
    out_emission = vec4(emissive, 0.0);
}
