#version 330 core
// Geometry pass with normal mapping: the tangent-space normal from the texture
// is taken to world space through the TBN frame, because the lighting pass
// works in world space.
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

// Any unit vector perpendicular to n (for a degenerate tangent).
vec3 any_perpendicular(vec3 n) {
    vec3 axis = abs(n.x) < 0.9 ? vec3(1.0, 0.0, 0.0) : vec3(0.0, 1.0, 0.0);
    return normalize(cross(axis, n));
}

vec3 mapped_normal(vec3 n) {
    // Gram-Schmidt: interpolation breaks orthogonality, so rebuild T against N
    // and B against both.
    vec3 t = v_world_tangent - n * dot(n, v_world_tangent);
    float t_len2 = dot(t, t);
    t = t_len2 > KIT_MIN_TANGENT_LENGTH_SQUARED ? t * inversesqrt(t_len2) : any_perpendicular(n);
    vec3 b = v_world_bitangent - n * dot(n, v_world_bitangent) - t * dot(t, v_world_bitangent);
    float b_len2 = dot(b, b);
    b = b_len2 > KIT_MIN_TANGENT_LENGTH_SQUARED ? b * inversesqrt(b_len2) : cross(n, t);
    vec3 texel = texture(u_normal_texture, kit_normal_uv(v_texcoords)).xyz;
    vec3 tangent_normal = (2.0 * texel - 1.0) * vec3(u_normal_scale, u_normal_scale, 1.0);
    vec3 world = mat3(t, b, n) * tangent_normal;
    float len2 = dot(world, world);
    return len2 > KIT_MIN_TANGENT_LENGTH_SQUARED ? world * inversesqrt(len2) : n;
}

void main() {
    // glTF: factor * texel * COLOR_0, alpha included (it decides MASK coverage).
    vec4 base_color = u_base_color_factor * texture(u_base_color_texture, kit_base_color_uv(v_texcoords)) * v_color;
    kit_alpha_discard(base_color.a);  // MASK: below the cutoff, no surface here
    vec4 metallic_roughness = texture(u_metallic_roughness_texture, kit_metallic_roughness_uv(v_texcoords));
    float metallic = u_metallic_factor * metallic_roughness.b;
    float roughness = u_roughness_factor * metallic_roughness.g;
    vec3 emissive = u_emissive_factor * texture(u_emissive_texture, kit_emissive_uv(v_texcoords)).rgb;

    vec3 n = normalize(v_world_normal);
    if (u_has_normal_texture) n = mapped_normal(n);

    out_position = vec4(v_world_position, 1.0);
    // Flipping the mapped normal is flipping the whole tangent frame: the back of a
    // bumpy surface seen from behind.
    out_normal = vec4(kit_facing_normal(n), 0.0);  // flipped on a double-sided back face
    out_albedo = base_color;  // .a: the base colour alpha
    out_material = vec4(metallic, roughness, 0.0, 1.0);  // .b unused, .a = coverage mask
    out_emission = vec4(emissive, 0.0);
}
