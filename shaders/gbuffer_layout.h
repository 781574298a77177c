// G-buffer layout: the one place both C++ (common/render/gbuffer.cpp) and GLSL
// (every geometry and lighting shader, via #include "gbuffer_layout.h") read.
// Only #define lines live here so the file is valid in both languages.
//
// Attachment           Format        .rgb / .r .g .b          .a
// 0 KIT_GBUF_POSITION  RGBA16F       world-space position     1 where covered
// 1 KIT_GBUF_NORMAL    RGBA16F       world-space unit normal  0 (unused)
//                                    (facing the viewer on a double-sided back face)
// 2 KIT_GBUF_ALBEDO    RGBA8         linear base colour       base colour alpha
// 3 KIT_GBUF_MATERIAL  RGBA16F       metallic, roughness,     coverage mask
//                                    0 (.b unused)            (1 = surface, 0 = clear)
// 4 KIT_GBUF_EMISSION  RGBA16F       emitted radiance L_e     0 (unused)
// depth                DEPTH24 texture (readable by later passes)
//
// Emitted radiance is a colour: L_e = emissiveFactor * emissiveStrength * emissive
// texel, stored as it is. It needs a float target of its own: it exceeds 1 (the
// emissive strength), so it cannot share the RGBA8 albedo, and the material
// attachment has one free channel, not three. (Before, one scalar in material.b
// was multiplied by the albedo: it lost the emissive colour, and a black base
// colour never glowed.)
//
// Albedo alpha: the base colour alpha (factor * texel * COLOR_0). The lighting pass ignores
// it; the forward pass (common/render/forward_pass.h) blends BLEND materials by it: from
// stage 2 they are drawn into a layer G-buffer of their own, after lighting, not
// into this one. MASK fragments below their cutoff are discarded in the geometry
// pass and leave the attachments as cleared (mask 0).
#ifndef KIT_GBUFFER_LAYOUT_H
#define KIT_GBUFFER_LAYOUT_H

#define KIT_GBUF_POSITION 0
#define KIT_GBUF_NORMAL 1
#define KIT_GBUF_ALBEDO 2
#define KIT_GBUF_MATERIAL 3
#define KIT_GBUF_EMISSION 4
#define KIT_GBUF_COUNT 5

// Texture units the framework binds the G-buffer to for full-screen passes.
#define KIT_UNIT_GBUF_POSITION 0
#define KIT_UNIT_GBUF_NORMAL 1
#define KIT_UNIT_GBUF_ALBEDO 2
#define KIT_UNIT_GBUF_MATERIAL 3
#define KIT_UNIT_GBUF_EMISSION 4
#define KIT_UNIT_GBUF_DEPTH 5
#define KIT_UNIT_LIGHTS 6
#define KIT_UNIT_HDR 7
#define KIT_UNIT_BLOOM 8
#define KIT_UNIT_LDR 9
// Lab 6 (image-based lighting): the environment and what is precomputed from it
// (common/render/ibl.h, shaders/environment.glsl).
#define KIT_UNIT_ENVIRONMENT 10
#define KIT_UNIT_IRRADIANCE 11
#define KIT_UNIT_PREFILTERED 12
#define KIT_UNIT_BRDF_LUT 13
// The prefiltered radiance map holds KIT_PREFILTER_LEVELS mip levels; level k is
// prefiltered for perceptual roughness k / (KIT_PREFILTER_LEVELS - 1).
#define KIT_PREFILTER_LEVELS 6
// The BRDF table is KIT_BRDF_LUT_SIZE x KIT_BRDF_LUT_SIZE texels; texel i holds the
// value at i / (KIT_BRDF_LUT_SIZE - 1), so the grid includes n.v = 0 and 1.
#define KIT_BRDF_LUT_SIZE 64

// Texture units for material textures in the geometry pass.
#define KIT_UNIT_BASE_COLOR 0
#define KIT_UNIT_METALLIC_ROUGHNESS 1
#define KIT_UNIT_NORMAL_MAP 2
#define KIT_UNIT_EMISSIVE 3

// glTF alphaMode, as the framework sets u_alpha_mode per draw (material_modes.glsl).
#define KIT_ALPHA_OPAQUE 0
#define KIT_ALPHA_MASK 1
#define KIT_ALPHA_BLEND 2

// Vertex attribute locations.
#define KIT_ATTR_POSITION 0
#define KIT_ATTR_NORMAL 1
#define KIT_ATTR_TEXCOORD 2   // UV slot 0 (Vertex::texcoord)
#define KIT_ATTR_TANGENT 3
#define KIT_ATTR_COLOR 4  // glTF COLOR_0 (linear rgba; white when the file has none)
#define KIT_ATTR_TEXCOORD1 5  // UV slot 1 (Vertex::texcoord1; zero when no texture reads a second UV set)

// Lights live in a uniform block bound at KIT_BLOCK_LIGHTS (lights.glsl), KIT_LIGHT_TEXELS
// vec4 per light: 256 lights of 4 vec4 are 16 KiB, the uniform block size every GL 3.3
// implementation must allow. With more lights they live in an RGBA32F texture (one row
// each), the framework defines KIT_LIGHTS_IN_TEXTURE, and shaders read that instead.
#define KIT_LIGHT_TEXELS 4
#define KIT_LIGHT_BLOCK_CAPACITY 256
#define KIT_BLOCK_LIGHTS 0
#define KIT_LIGHT_POINT 0
#define KIT_LIGHT_SPOT 1
#define KIT_LIGHT_DIRECTIONAL 2  // glTF "directional": parallel rays along `direction`

#endif
