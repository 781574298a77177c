#version 330 core
// Tiled deferred, pass 2: each pixel sums the lights of its tile's list whose
// sphere holds it; the radius test is the light volumes' one, so both methods drop
// the same terms. A full-screen fragment pass, not a compute dispatch: llvmpipe
// runs the same shading faster per pixel and light in a fragment shader.
#extension GL_ARB_shader_storage_buffer_object : require
#include "bench_layout.h"
#include "shade.glsl"
#include "light_bounds.glsl"
#include "tiled_lists.glsl"

in vec2 v_uv;
out vec4 out_color;

void main() {
    ivec2 pixel = ivec2(gl_FragCoord.xy);
    Surface s = read_surface(pixel);
    if (!s.covered) {
        out_color = vec4(u_count_lights ? vec3(0.0) : u_clear_color, 1.0);
        return;
    }
    vec3 v = view_direction(s);
    vec3 radiance = u_count_lights ? vec3(0.0) : s.emission;
    int base = tile_base(pixel / KIT_TILE_SIZE);
    int count = tile_lights[base];
    for (int k = 1; k <= count; ++k) {
        // The radius test reads the one bounds texel; only lights that pass it are
        // fetched whole and shaded.
        int index = tile_lights[base + k];
        LightBound bound = light_bound(index);
        vec3 from_light = s.position - (bound.center - u_shading_origin);
        if (dot(from_light, from_light) <= bound.radius * bound.radius)
            radiance += u_count_lights ? vec3(1.0) : shade_light(s, v, kit_light(index));
    }
    out_color = vec4(min(radiance, vec3(KIT_HDR_MAX)), 1.0);
}
