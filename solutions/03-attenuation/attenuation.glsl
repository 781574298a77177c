// Light falloff: the lecture's inverse square, with the simple 1/(1 + d^2) model selectable.
// Intensity units: see handouts/03-attenuation.md. Spot falloff: smoothstep
// between the outer (penumbra) and inner (umbra) cone.
#include "lights.glsl"
#include "uniforms.glsl"
#include "guards.glsl"
#include "math.glsl"

// 0 outside the outer cone, 1 inside the inner cone, smoothstep in between.
float spot_cone_factor(Light light, vec3 p) {
    vec3 from_light = p - light.position;
    from_light *= inversesqrt(max(dot(from_light, from_light), KIT_MIN_DISTANCE_SQUARED));
    float cos_angle = dot(from_light, light.direction);
    // Own smoothstep: GLSL's smoothstep(e0, e1, x) is undefined when e0 == e1 (inner == outer).
    float t = clamp((cos_angle - light.cos_outer) / max(light.cos_inner - light.cos_outer, KIT_MIN_CONE_COS_GAP), 0.0, 1.0);
    return t * t * (3.0 - 2.0 * t);
}

// Radiance arriving at world position p from `light`.
vec3 light_radiance(Light light, vec3 p) {
    // A directional light's intensity is already the illuminance on a surface facing
    // it: no distance (it is infinitely far), no cone, no range, under both models.
    if (light.type == KIT_LIGHT_DIRECTIONAL) return light.color * light.intensity;
    vec3 to_light = light.position - p;
    float r2 = max(dot(to_light, to_light), KIT_MIN_DISTANCE_SQUARED);
    float intensity;
    if (u_attenuation_model == 1) {
        intensity = light.intensity / (1.0 + r2);  // the simple model: 1 / (1 + d^2)
    } else if (light.type == KIT_LIGHT_SPOT) {
        // I = flux / (2 pi r^2 (1 - (cos umbra + cos penumbra) / 2))
        float solid = max(1.0 - 0.5 * (light.cos_inner + light.cos_outer), KIT_MIN_SPOT_SOLID_ANGLE);
        intensity = light.flux / (2.0 * KIT_PI * r2 * solid);
    } else {
        intensity = light.flux / (4.0 * KIT_PI * r2);  // I = flux / (4 pi r^2)
    }
    if (light.type == KIT_LIGHT_SPOT) intensity *= spot_cone_factor(light, p);
    // glTF range (lights.glsl), given: 1 for lights without one.
    return light.color * intensity * kit_range_window(light, p);
}
