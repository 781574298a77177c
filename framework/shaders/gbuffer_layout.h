// G-buffer layout: the one place both C++ (framework/gbuffer.cpp) and GLSL
// (every geometry and lighting shader, via #include "gbuffer_layout.h") read.
// Only #define lines live here so the file is valid in both languages.
//
// Attachment           Format        .rgb / .r .g .b          .a
// 0 KIT_GBUF_POSITION  RGBA16F       world-space position     1 where covered
// 1 KIT_GBUF_NORMAL    RGBA16F       world-space unit normal  0 (unused)
// 2 KIT_GBUF_ALBEDO    RGBA8         linear base colour       1 (unused)
// 3 KIT_GBUF_MATERIAL  RGBA16F       metallic, roughness,     coverage mask
//                                    emission strength        (1 = surface, 0 = clear)
// depth                DEPTH24 texture (readable by later passes)
//
// Emitted radiance is reconstructed as  L_e = emission * albedo : one scalar
// channel carries glTF's emissiveFactor * emissiveStrength (its max component).
#ifndef KIT_GBUFFER_LAYOUT_H
#define KIT_GBUFFER_LAYOUT_H

#define KIT_GBUF_POSITION 0
#define KIT_GBUF_NORMAL 1
#define KIT_GBUF_ALBEDO 2
#define KIT_GBUF_MATERIAL 3
#define KIT_GBUF_COUNT 4

// Texture units the framework binds the G-buffer to for full-screen passes.
#define KIT_UNIT_GBUF_POSITION 0
#define KIT_UNIT_GBUF_NORMAL 1
#define KIT_UNIT_GBUF_ALBEDO 2
#define KIT_UNIT_GBUF_MATERIAL 3
#define KIT_UNIT_GBUF_DEPTH 4
#define KIT_UNIT_LIGHTS 5
#define KIT_UNIT_HDR 6
#define KIT_UNIT_BLOOM 7
#define KIT_UNIT_LDR 8

// Texture units for material textures in the geometry pass.
#define KIT_UNIT_BASE_COLOR 0
#define KIT_UNIT_METALLIC_ROUGHNESS 1
#define KIT_UNIT_NORMAL_MAP 2
#define KIT_UNIT_EMISSIVE 3

// Vertex attribute locations.
#define KIT_ATTR_POSITION 0
#define KIT_ATTR_NORMAL 1
#define KIT_ATTR_TEXCOORD 2
#define KIT_ATTR_TANGENT 3

// Lights live in an RGBA32F texture, KIT_LIGHT_TEXELS texels per light (one row each).
#define KIT_LIGHT_TEXELS 4
#define KIT_LIGHT_POINT 0
#define KIT_LIGHT_SPOT 1

#endif
