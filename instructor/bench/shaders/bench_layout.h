// The bench's G-buffer layouts and method constants: read by both C++
// (instructor/bench/bench_gbuffer.cpp, instructor/bench/bench_renderer.cpp) and GLSL (instructor/bench/shaders/*),
// so only #define lines live here.
//
// Layout family KIT_BENCH_LAYOUT_FAT: the five attachments of gbuffer_layout.h
// (position, normal, albedo, material, emission) in any precision; the reference (RGBA32F
// position and normal) and seed 002's layout (RGBA16F, the labs' GBuffer) are both
// FAT and read by the same code.
//
// Layout family KIT_BENCH_LAYOUT_LEAN: no position attachment.
//   attachment 0  KIT_LEAN_NORMAL    RG16 or RG8 unorm   octahedral unit normal
//   attachment 1  KIT_LEAN_ALBEDO    RGBA8               linear base colour
//   attachment 2  KIT_LEAN_MATERIAL  RGBA8               metallic, roughness, 0 (unused),
//                                                        coverage mask
//   attachment 3  KIT_LEAN_EMISSION  RGBA8               emitted radiance, each channel
//                                                        as e/(1+e) (lean_encoding.glsl)
//   depth         DEPTH24 texture: the position is reconstructed from it through
//                 the inverse view-projection (camera-relative, see surface.glsl).
#ifndef KIT_BENCH_LAYOUT_H
#define KIT_BENCH_LAYOUT_H

#define KIT_BENCH_LAYOUT_FAT 0
#define KIT_BENCH_LAYOUT_LEAN 1

#define KIT_LEAN_NORMAL 0
#define KIT_LEAN_ALBEDO 1
#define KIT_LEAN_MATERIAL 2
#define KIT_LEAN_EMISSION 3
#define KIT_LEAN_COUNT 4

// Tiled deferred: square tiles of KIT_TILE_SIZE^2 pixels. tiled_cull.comp runs one
// invocation per tile, in work groups of KIT_TILE_GROUP^2, and writes the tile's
// light list; tiled_shade.frag shades every pixel from its tile's list.
#define KIT_TILE_SIZE 16
#define KIT_TILE_GROUP 8

// Shader-storage binding of the tiles' light lists.
#define KIT_TILE_LIGHTS_BINDING 0

// Texture unit of the culling methods' light bounds (light_bounds.glsl): after
// gbuffer_layout.h's units.
#define KIT_UNIT_LIGHT_BOUNDS 10

#endif
