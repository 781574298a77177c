// Lab 3 - light falloff. See handouts/03-attenuation.md.
#include "lights.glsl"
#include "uniforms.glsl"
#include "guards.glsl"
#include "math.glsl"

// TODO(lab 3): 0 outside the outer cone, 1 inside the inner cone, smoothstep
//              between them. Mind inner == outer (KIT_MIN_CONE_COS_GAP).
float spot_cone_factor(Light light, vec3 p) {
    vec3 from_light = normalize(p - light.position);
    return dot(from_light, light.direction) < light.cos_outer ? 0.0 : 1.0;
}

// Radiance arriving at world position p from `light`.
vec3 light_radiance(Light light, vec3 p) {
    // TODO(lab 3): u_attenuation_model == 0: point I = flux / (4 pi r^2),
    //              spot I = flux / (2 pi r^2 (1 - (cos_inner + cos_outer) / 2));
    //              u_attenuation_model == 1: intensity / (1 + d^2).
    //              Floor r^2 with KIT_MIN_DISTANCE_SQUARED. A KIT_LIGHT_DIRECTIONAL
    //              light (intensity in lux) has no falloff and no cone.
    float intensity = light.intensity;  // no falloff yet
    if (light.type == KIT_LIGHT_SPOT) intensity *= spot_cone_factor(light, p);
    // glTF range (lights.glsl), given: 1 for lights without one.
    return light.color * intensity * kit_range_window(light, p);
}
