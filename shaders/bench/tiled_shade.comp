#version 330 core
// Tiled deferred, pass 2: each pixel sums the lights of its tile's list whose
// sphere holds it; the radius test is the light volumes' one, so both methods drop
// the same terms.
#extension GL_ARB_compute_shader : require
#extension GL_ARB_shader_image_load_store : require
#extension GL_ARB_shader_storage_buffer_object : require
#include "bench_layout.h"
#include "shade.glsl"
#include "light_bounds.glsl"
#include "tiled_lists.glsl"

layout(local_size_x = KIT_TILE_GROUP, local_size_y = KIT_TILE_GROUP) in;
layout(rgba16f) uniform writeonly image2D u_hdr_image;

void main() {
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(pixel, ivec2(u_resolution)))) return;
    Surface s = read_surface(pixel);
    if (!s.covered) {
        imageStore(u_hdr_image, pixel, vec4(u_count_lights ? vec3(0.0) : u_clear_color, 1.0));
        return;
    }
    vec3 v = view_direction(s);
    vec3 radiance = u_count_lights ? vec3(0.0) : s.emission * s.albedo;
    int base = tile_base(pixel / KIT_TILE_SIZE);
    int count = tile_lights[base];
    for (int k = 1; k <= count; ++k) {
        Light light = kit_light(tile_lights[base + k]);
        vec3 from_light = s.position - light_position(light);
        float radius = light_cutoff_radius(light);
        if (dot(from_light, from_light) <= radius * radius)
            radiance += u_count_lights ? vec3(1.0) : shade_light(s, v, light);
    }
    imageStore(u_hdr_image, pixel, vec4(min(radiance, vec3(KIT_HDR_MAX)), 1.0));
}
