// The culling methods' per-light bounds: light volumes (volume.vert) and tiled
// deferred (tiled_cull.comp, tiled_shade.frag) drop a light wherever the surface
// lies farther from it than its cut-off radius. The radius is computed once per
// light on the CPU (bench_renderer.h light_cutoff_radius: the bound and where it is
// exact) and read here as one texel: the light's world position and the radius.
#include "bench_layout.h"

uniform sampler2D u_light_bounds;
// Counting mode (kit-bench's lights-per-pixel figure): each light that passes the
// radius test adds 1 instead of its radiance.
uniform bool u_count_lights;

struct LightBound {
    vec3 center;   // world space
    float radius;  // light_cutoff_radius
};

LightBound light_bound(int i) {
    vec4 t = texelFetch(u_light_bounds, ivec2(0, i), 0);
    return LightBound(t.xyz, t.w);
}
