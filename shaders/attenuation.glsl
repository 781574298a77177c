// Stage 2's light model: no distance falloff yet. L_i = colour * intensity for
// every light type, directional included, and a spot light lights only inside
// its outer cone. Lab 3 replaces this file.
#include "lights.glsl"
#include "uniforms.glsl"

// Radiance arriving at world position p from `light`.
vec3 light_radiance(Light light, vec3 p) {
    vec3 radiance = light.color * light.intensity;
    if (light.type == KIT_LIGHT_SPOT) {
        vec3 to_point = normalize(p - light.position);
        if (dot(to_point, light.direction) < light.cos_outer) return vec3(0.0);
    }
    return radiance;
}
