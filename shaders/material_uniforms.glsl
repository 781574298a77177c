// The glTF metallic-roughness material uniforms the framework sets per draw.
// Textures are always bound: a material without one gets a white texel (or a
// flat normal), so factor * texel works.

// Which material features the helpers below compile. The renderer builds one program
// per feature set its scene's draws use and defines KIT_MATERIAL_VARIANT with the
// KIT_HAS_* of the draw's material (common/render/material_variants.h); the helpers give the
// same values either way, and cost nothing for a feature a draw does not use. A
// program built without KIT_MATERIAL_VARIANT has every feature.
#ifndef KIT_MATERIAL_VARIANT
#define KIT_HAS_UV1           // some texture reads UV slot 1
#define KIT_HAS_UV_TRANSFORM  // some texture has a KHR_texture_transform
#define KIT_HAS_ALPHA_MASK    // alphaMode MASK (kit_alpha_discard, material_modes.glsl)
#endif
uniform vec4 u_base_color_factor;
uniform float u_metallic_factor;
uniform float u_roughness_factor;
uniform vec3 u_emissive_factor;    // emissiveFactor * KHR_materials_emissive_strength
uniform float u_normal_scale;
uniform bool u_has_normal_texture;
uniform int u_alpha_mode;          // glTF alphaMode: KIT_ALPHA_OPAQUE, KIT_ALPHA_MASK or KIT_ALPHA_BLEND
uniform float u_alpha_cutoff;      // glTF alphaCutoff (default 0.5), used by KIT_ALPHA_MASK
uniform bool u_double_sided;       // glTF doubleSided: back faces drawn, their normal flipped
uniform sampler2D u_base_color_texture;          // sRGB format: sampling returns linear colour
uniform sampler2D u_metallic_roughness_texture;  // glTF: roughness in G, metallic in B (linear)
uniform sampler2D u_normal_texture;              // tangent-space normal, stored as (n + 1) / 2
uniform sampler2D u_emissive_texture;            // sRGB format

// Each texture's UV, as its glTF texture reference says, indexed by the texture's
// unit (KIT_UNIT_*): which of the vertex's two UV slots it reads (texCoord) and
// its KHR_texture_transform as the loader's matrix (kit::texture_transform_matrix,
// which turns the UVs the way the Khronos sample models do, not the way the
// extension README's GLSL listing does: glTF issue #1563). An untransformed
// texture gets the identity.
uniform int u_texture_uv_slot[4];
uniform mat3 u_texture_uv_transform[4];

// The UV a material texture samples. `texcoords` holds both UV slots as the vertex
// stage passes them on: .xy slot 0 (a_texcoord0), .zw slot 1 (a_texcoord1).
vec2 kit_texture_uv(int unit, vec4 texcoords) {
#ifdef KIT_HAS_UV1
    vec2 uv = u_texture_uv_slot[unit] == 1 ? texcoords.zw : texcoords.xy;
#else
    vec2 uv = texcoords.xy;  // every texture of the draw reads slot 0
#endif
#ifdef KIT_HAS_UV_TRANSFORM
    uv = (u_texture_uv_transform[unit] * vec3(uv, 1.0)).xy;
#endif
    return uv;
}
vec2 kit_base_color_uv(vec4 texcoords) { return kit_texture_uv(KIT_UNIT_BASE_COLOR, texcoords); }
vec2 kit_metallic_roughness_uv(vec4 texcoords) { return kit_texture_uv(KIT_UNIT_METALLIC_ROUGHNESS, texcoords); }
vec2 kit_normal_uv(vec4 texcoords) { return kit_texture_uv(KIT_UNIT_NORMAL_MAP, texcoords); }
vec2 kit_emissive_uv(vec4 texcoords) { return kit_texture_uv(KIT_UNIT_EMISSIVE, texcoords); }
