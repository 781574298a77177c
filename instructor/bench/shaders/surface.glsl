// One G-buffer texel as the shading inputs, whatever the layout (bench_layout.h).
// Every bench lighting shader (full-screen loop, light volumes, tiled compute) reads
// the G-buffer only through read_surface, so the layouts differ in this file alone.
#include "bench_layout.h"
#include "uniforms.glsl"
#include "lean_encoding.glsl"

uniform int u_gbuffer_layout;  // KIT_BENCH_LAYOUT_FAT or KIT_BENCH_LAYOUT_LEAN
// Shading happens relative to this world point: 0 for the FAT layouts (their
// position attachment holds world positions), the camera for the LEAN layout. Far
// from the origin (stability case 5), camera-relative values keep full float
// precision where absolute ones lose it.
uniform vec3 u_shading_origin;
// LEAN: clip space -> world space minus the camera (the view matrix without its
// translation), computed in double on the CPU.
uniform mat4 u_inv_view_projection_relative;

struct Surface {
    bool covered;      // false where the geometry pass wrote nothing (mask 0)
    vec3 position;     // world position - u_shading_origin
    vec3 normal;       // unit, world orientation
    vec3 albedo;       // linear base colour
    float metallic;
    float roughness;   // perceptual roughness
    vec3 emission;     // emitted radiance L_e
};

// Coverage and position only (one texel fetch): what a light volume or a tile
// needs to decide whether a light reaches the pixel at all.
bool read_position(ivec2 pixel, out vec3 position) {
    if (u_gbuffer_layout == KIT_BENCH_LAYOUT_LEAN) {
        float depth = texelFetch(u_gbuffer_depth, pixel, 0).r;
        // The geometry pass rasterised at pixel centres, so the depth belongs to the
        // centre's NDC position.
        vec3 ndc = vec3((vec2(pixel) + 0.5) / u_resolution, depth) * 2.0 - 1.0;
        vec4 relative = u_inv_view_projection_relative * vec4(ndc, 1.0);
        position = relative.xyz / relative.w;
        return depth < 1.0;  // cleared to 1 (the far plane) where nothing was drawn
    }
    vec4 stored = texelFetch(u_gbuffer_position, pixel, 0);
    position = stored.xyz - u_shading_origin;
    return stored.a >= 0.5;  // gbuffer_layout.h: position.a is 1 where covered, as the mask
}

Surface read_surface(ivec2 pixel) {
    Surface s;
    s.covered = read_position(pixel, s.position);
    vec4 material = texelFetch(u_gbuffer_material, pixel, 0);
    s.albedo = texelFetch(u_gbuffer_albedo, pixel, 0).rgb;
    s.metallic = material.r;
    s.roughness = material.g;
    if (u_gbuffer_layout == KIT_BENCH_LAYOUT_LEAN) {
        s.normal = oct_decode(texelFetch(u_gbuffer_normal, pixel, 0).rg);
        s.emission = emission_decode(texelFetch(u_gbuffer_emission, pixel, 0).rgb);
    } else {
        s.normal = normalize(texelFetch(u_gbuffer_normal, pixel, 0).xyz);
        s.emission = texelFetch(u_gbuffer_emission, pixel, 0).rgb;
    }
    return s;
}
