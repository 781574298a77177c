// The geometry pass's material and normal-map evaluation for the bench's own
// geometry shaders (the lean G-buffer and forward shading). It is
// solutions/04-normalmap/gbuffer.frag's computation: that file is a complete
// shader (it declares #version and main), so it cannot be included.
// instructor/tests/test_bench_methods.cpp checks the lean layout and forward shading against
// the labs' G-buffer, so the two copies cannot drift apart unnoticed.
#include "gbuffer_layout.h"

#include "geometry_uniforms.glsl"
#include "guards.glsl"
#include "material_modes.glsl"

// The varyings of solutions/04-normalmap/gbuffer.vert.
in vec3 v_world_position;
in vec3 v_world_normal;
in vec3 v_world_tangent;
in vec3 v_world_bitangent;
in vec4 v_texcoords;  // both UV slots; kit_base_color_uv(v_texcoords) and the like pick a texture's own
in vec4 v_color;  // glTF COLOR_0

struct SurfaceInputs {
    vec3 normal;      // unit, world space, normal map applied
    vec3 albedo;
    float alpha;      // base colour alpha (albedo.a of the labs' G-buffer)
    float metallic;
    float roughness;
    vec3 emission;    // emitted radiance L_e
};

vec3 any_perpendicular(vec3 n) {
    vec3 axis = abs(n.x) < 0.9 ? vec3(1.0, 0.0, 0.0) : vec3(0.0, 1.0, 0.0);
    return normalize(cross(axis, n));
}

vec3 mapped_normal(vec3 n) {
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

SurfaceInputs surface_inputs() {
    SurfaceInputs m;
    vec4 base_color = u_base_color_factor * texture(u_base_color_texture, kit_base_color_uv(v_texcoords)) * v_color;
    vec4 metallic_roughness = texture(u_metallic_roughness_texture, kit_metallic_roughness_uv(v_texcoords));
    kit_alpha_discard(base_color.a);
    m.albedo = base_color.rgb;
    m.alpha = base_color.a;
    m.metallic = u_metallic_factor * metallic_roughness.b;
    m.roughness = u_roughness_factor * metallic_roughness.g;
    m.emission = u_emissive_factor * texture(u_emissive_texture, kit_emissive_uv(v_texcoords)).rgb;
    m.normal = normalize(v_world_normal);
    if (u_has_normal_texture) m.normal = mapped_normal(m.normal);
    m.normal = kit_facing_normal(m.normal);
    return m;
}
