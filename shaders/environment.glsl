// Lab 6's environment and the maps the lab precomputes from it (common/render/ibl.h).
//
// Equirectangular convention (the instructors' CPU reference of lab 6 mirrors it):
// u runs with the azimuth phi = (u - 0.5) 2 pi, u = 0.5 looking along -Z and
// u = 0.75 along +X; the polar angle from +Y is theta = (1 - t) pi, where t is GL's
// texture coordinate, so the image's top row (uploaded last) is the sky overhead.
// A direction is (sin theta sin phi, cos theta, -sin theta cos phi).
#include "gbuffer_layout.h"
#include "guards.glsl"  // KIT_MIN_DIRECTION_LENGTH_SQUARED
#include "math.glsl"

uniform sampler2D u_environment;  // radiance, RGBA32F, mipmapped (box filter), wraps in u
uniform sampler2D u_irradiance;   // irradiance E(n) = integral of L(l) max(n.l, 0), equirectangular
uniform sampler2D u_prefiltered;  // level k: radiance prefiltered for roughness k / (KIT_PREFILTER_LEVELS - 1)
uniform sampler2D u_brdf_lut;     // (A, B, C) over (n.v, roughness): handouts/06-ibl.md

// The texture coordinate of direction d (any length; a zero vector maps to the sky's pole).
vec2 kit_equirect_uv(vec3 d) {
    float length_squared = dot(d, d);
    if (length_squared < KIT_MIN_DIRECTION_LENGTH_SQUARED) return vec2(0.5, 1.0);
    d *= inversesqrt(length_squared);
    // GLSL leaves atan(0, 0) undefined, and straight up or down (a flat floor's normal) is
    // there: llvmpipe gives 0, SwiftShader pi, the opposite side of the pole's row (a floor
    // 1 % brighter). 0 here, as in the CPU reference.
    float phi = (d.x == 0.0 && d.z == 0.0) ? 0.0 : atan(d.x, -d.z);  // in [-pi, pi]
    float theta = acos(clamp(d.y, -1.0, 1.0));    // rounding can leave |d.y| a hair above 1
    return vec2(phi / (2.0 * KIT_PI) + 0.5, 1.0 - theta / KIT_PI);
}

// The unit direction at texture coordinate uv. Normalized after sin and cos: GLSL ES 3.00
// and Vulkan let them err by 2^-11 (SwiftShader and GPUs do, llvmpipe barely), and lab 6's
// prefilter at its lowest roughness needs n.h within alpha^2 = 4e-6 of 1 where h is n
// (a direction 1e-4 too long put the sun's reflection 10 degrees away on SwiftShader).
vec3 kit_equirect_direction(vec2 uv) {
    float phi = (uv.x - 0.5) * 2.0 * KIT_PI;
    float theta = (1.0 - uv.y) * KIT_PI;
    float sin_theta = sin(theta);
    return normalize(vec3(sin_theta * sin(phi), cos(theta), -sin_theta * cos(phi)));
}

// The solid angle of every texel of row `row` (GL's row order, 0 at the bottom) of an
// equirectangular image of `size` texels: (2 pi / width) (cos theta_top - cos theta_bottom).
// The rows of an image sum to 4 pi; a texel near a pole covers far less than one at the horizon.
// Written as (2 pi / width) 2 sin(theta_mid) sin(delta / 2), delta = pi / height, with the
// small sine from its series: GLSL ES 3.00 lets cos err by 2^-11, a tenth of the difference
// of two rows' cosines at 64 rows, and SwiftShader's irradiance came out 0.3 % off.
float kit_equirect_texel_solid_angle(int row, ivec2 size) {
    float half_delta = 0.5 * KIT_PI / float(size.y);
    float theta_mid = (float(size.y - row) - 0.5) * KIT_PI / float(size.y);
    float h2 = half_delta * half_delta;
    float sin_half_delta = half_delta * (1.0 - h2 / 6.0 * (1.0 - h2 / 20.0));  // error below h^7/5040
    return 2.0 * KIT_PI / float(size.x) * 2.0 * sin(theta_mid) * sin_half_delta;
}

// Radiance arriving from direction d: level 0, bilinear. The level is explicit: with
// texture()'s implicit level, the jump of u from 1 to 0 at the wrap looks like a
// texture-wide derivative, and that column of pixels would read the smallest mip (a seam).
vec3 kit_environment_radiance(vec3 d) {
    return textureLod(u_environment, kit_equirect_uv(d), 0.0).rgb;
}

// E(n), from the irradiance map.
vec3 kit_irradiance(vec3 n) {
    return textureLod(u_irradiance, kit_equirect_uv(n), 0.0).rgb;
}

// Prefiltered radiance around reflection direction r: between the two levels
// nearest `perceptual_roughness` (trilinear filtering blends them).
vec3 kit_prefiltered_radiance(vec3 r, float perceptual_roughness) {
    float level = clamp(perceptual_roughness, 0.0, 1.0) * float(KIT_PREFILTER_LEVELS - 1);
    return textureLod(u_prefiltered, kit_equirect_uv(r), level).rgb;
}

// The grid value (n.v or roughness) a BRDF table texel stands for, from the texture
// coordinate of its centre: texel i holds i / (KIT_BRDF_LUT_SIZE - 1).
float kit_brdf_lut_grid_value(float texture_coordinate) {
    return (texture_coordinate * float(KIT_BRDF_LUT_SIZE) - 0.5) / float(KIT_BRDF_LUT_SIZE - 1);
}

// The BRDF table (A, B, C) at (n.v, perceptual roughness), bilinear between grid values.
vec3 kit_brdf_lut(float n_dot_v, float perceptual_roughness) {
    vec2 grid = clamp(vec2(n_dot_v, perceptual_roughness), 0.0, 1.0);
    vec2 uv = (grid * float(KIT_BRDF_LUT_SIZE - 1) + 0.5) / float(KIT_BRDF_LUT_SIZE);
    return textureLod(u_brdf_lut, uv, 0.0).rgb;
}
