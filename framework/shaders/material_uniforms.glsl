// The glTF metallic-roughness material uniforms the framework sets per draw.
// Textures are always bound: a material without one gets a white texel (or a
// flat normal), so factor * texel works.
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
