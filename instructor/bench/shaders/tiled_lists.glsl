// The tiled method's per-tile light lists (shader storage, KIT_TILE_LIGHTS_BINDING):
// tile t owns the slots [t * (u_light_count + 1), (t + 1) * (u_light_count + 1)):
// the number of lights first, then their indices in increasing order, so every
// pixel sums its lights in the full-screen loop's order (a deterministic result).
#include "bench_layout.h"
#include "lights.glsl"

layout(std430) buffer TileLights {
    int tile_lights[];
};

#include "uniforms.glsl"

// Tiles across and down: partial tiles at the right and bottom edges count.
ivec2 tile_count() {
    return (ivec2(u_resolution) + KIT_TILE_SIZE - 1) / KIT_TILE_SIZE;
}

int tile_base(ivec2 tile) {
    return (tile.y * tile_count().x + tile.x) * (u_light_count + 1);
}
