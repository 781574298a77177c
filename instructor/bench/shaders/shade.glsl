// The reflectance equation's per-light term, shared by every bench lighting method.
// It is the body of solutions/02-lighting/lighting.frag's loop, written once as a
// function so a light volume or a tile can evaluate one light at a time; brdf.glsl
// and attenuation.glsl are the labs' own files (the resolver finds them in solutions/).
#include "surface.glsl"
#include "lights.glsl"
#include "guards.glsl"
#include "brdf.glsl"
#include "attenuation.glsl"

// Unit vector from the surface towards the camera.
vec3 view_direction(Surface s) {
    return normalize(u_camera_position - u_shading_origin - s.position);
}

// Light i's position in the shading space of Surface.position.
vec3 light_position(Light light) {
    return light.position - u_shading_origin;
}

// f(p, wo, wi) L_i (n.l) for one light, in linear HDR.
vec3 shade_light(Surface s, vec3 v, Light light) {
    light.position = light_position(light);
    vec3 l;
    if (light.type == KIT_LIGHT_DIRECTIONAL) {
        l = -light.direction;  // parallel rays: the same l at every p
    } else {
        vec3 to_light = light.position - s.position;
        // A light exactly at p has no direction: l = 0 makes n.l = 0 and it adds nothing.
        l = to_light * inversesqrt(max(dot(to_light, to_light), KIT_MIN_DISTANCE_SQUARED));
    }
    float n_dot_l = dot(s.normal, l);
    if (n_dot_l <= 0.0) return vec3(0.0);  // light below the surface
    return cook_torrance(s.normal, v, l, s.albedo, s.metallic, s.roughness) * light_radiance(light, s.position) * n_dot_l;
}

// L_e + the sum over lights [0, count), clamped to what RGBA16F holds: lighting.frag's result.
vec3 shade_all(Surface s, int count) {
    vec3 v = view_direction(s);
    vec3 radiance = s.emission;
    for (int i = 0; i < count; ++i) radiance += shade_light(s, v, kit_light(i));
    return min(radiance, vec3(KIT_HDR_MAX));
}
