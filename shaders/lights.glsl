// The scene's lights, as the framework uploads them: KIT_LIGHT_TEXELS vec4 per light,
// light i in row i of a uniform block of KIT_LIGHT_BLOCK_CAPACITY lights, or with more
// lights of an RGBA32F texture. The block is the fast path: a light read from it is a few
// loads where four texelFetch calls are four texture lookups. Only with more lights than the
// block holds does the framework define KIT_LIGHTS_IN_TEXTURE (and rebuild its programs):
// choosing per light inside the loop costs llvmpipe both reads.
#include "gbuffer_layout.h"
#include "light_specialisation.glsl"  // u_attenuation_model, kit_light_type, kit_light_range

uniform sampler2D u_light_texture;
uniform int u_light_count;
layout(std140) uniform KitLightBlock {
    vec4 u_light_block[KIT_LIGHT_BLOCK_CAPACITY * KIT_LIGHT_TEXELS];
};

struct Light {
    int type;          // KIT_LIGHT_POINT, KIT_LIGHT_SPOT or KIT_LIGHT_DIRECTIONAL
    vec3 position;     // world space (a directional light's node: not where its light comes from)
    vec3 direction;    // world space, where a spot or directional light points (unit)
    float range;       // glTF range, 0 = unlimited (always 0 for a directional light)
    vec3 color;        // linear RGB
    float intensity;   // glTF intensity: candela; lux (illuminance) for a directional light
    float cos_inner;   // cos(umbra/inner cone angle): full intensity inside
    float cos_outer;   // cos(penumbra/outer cone angle): no light outside
    float flux;        // radiant flux derived from intensity (handouts/03-attenuation.md); 0 for a
                       // directional light, which has no finite flux
    float volume_radius;  // lab 7: the radius of its light volume, where its light is cut off
                          // (common/render/light_volumes.h); 0 for a directional light
};

Light kit_light(int i) {
#ifdef KIT_LIGHTS_IN_TEXTURE
    vec4 t0 = texelFetch(u_light_texture, ivec2(0, i), 0);
    vec4 t1 = texelFetch(u_light_texture, ivec2(1, i), 0);
    vec4 t2 = texelFetch(u_light_texture, ivec2(2, i), 0);
    vec4 t3 = texelFetch(u_light_texture, ivec2(3, i), 0);
#else
    int k = i * KIT_LIGHT_TEXELS;
    vec4 t0 = u_light_block[k];
    vec4 t1 = u_light_block[k + 1];
    vec4 t2 = u_light_block[k + 2];
    vec4 t3 = u_light_block[k + 3];
#endif
    Light light;
    // Constants when every light of the frame allows it (light_specialisation.glsl).
    light.type = kit_light_type(t0);
    light.position = t0.xyz;
    light.direction = t1.xyz;
    light.range = kit_light_range(t1);
    light.color = t2.rgb;
    light.intensity = t2.w;
    light.cos_inner = t3.x;
    light.cos_outer = t3.y;
    light.flux = t3.z;
    light.volume_radius = t3.w;
    return light;
}

// glTF KHR_lights_punctual's `range`: the spec's recommended window
// clamp(1 - (d / range)^4, 0, 1) takes the light to exactly 0 at d = range, so a
// light volume or tile list of that radius drops nothing. range <= 0 is unlimited
// (window 1), and so is a directional light (glTF: range does not apply; it
// reaches everywhere). Lab 3's light_radiance multiplies its falloff by this.
float kit_range_window(Light light, vec3 p) {
    if (light.type == KIT_LIGHT_DIRECTIONAL || light.range <= 0.0) return 1.0;
    vec3 offset = light.position - p;
    float q = dot(offset, offset) / (light.range * light.range);  // (d / range)^2
    return clamp(1.0 - q * q, 0.0, 1.0);
}
