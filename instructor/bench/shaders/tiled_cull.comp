#version 330 core
// Tiled deferred, pass 1: one invocation per tile bounds the tile's surfaces by a
// box in shading space and lists the lights whose cut-off sphere (light_bounds.glsl)
// touches it. No shared memory and no barriers: on a CPU rasteriser (llvmpipe)
// the barrier-synchronised single-pass form costs more than it saves.
// GL 3.3 has no compute stage: these extensions are core in GL 4.3, which every
// context the bench runs this on (llvmpipe: 4.5) provides.
#extension GL_ARB_compute_shader : require
#extension GL_ARB_shader_storage_buffer_object : require
#include "bench_layout.h"
#include "surface.glsl"
#include "light_bounds.glsl"
#include "tiled_lists.glsl"

layout(local_size_x = KIT_TILE_GROUP, local_size_y = KIT_TILE_GROUP) in;

// Start of an empty box: min > max on every axis until a covered pixel is seen.
const float KIT_FLOAT_MAX = 3.402823e38;

void main() {
    ivec2 tile = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(tile, tile_count()))) return;
    ivec2 first = tile * KIT_TILE_SIZE;
    ivec2 last = min(first + KIT_TILE_SIZE, ivec2(u_resolution));
    vec3 box_min = vec3(KIT_FLOAT_MAX), box_max = vec3(-KIT_FLOAT_MAX);
    for (int y = first.y; y < last.y; ++y) {
        for (int x = first.x; x < last.x; ++x) {
            vec3 p;
            if (read_position(ivec2(x, y), p)) {
                box_min = min(box_min, p);
                box_max = max(box_max, p);
            }
        }
    }
    int base = tile_base(tile);
    int count = 0;
    if (box_min.x <= box_max.x) {
        for (int i = 0; i < u_light_count; ++i) {
            LightBound bound = light_bound(i);
            vec3 center = bound.center - u_shading_origin;
            vec3 gap = center - clamp(center, box_min, box_max);  // sphere-to-box distance
            if (dot(gap, gap) <= bound.radius * bound.radius) tile_lights[base + 1 + count++] = i;
        }
    }
    tile_lights[base] = count;
}
