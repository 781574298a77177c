// Uniforms the framework sets for every full-screen pass. Include this file
// rather than declaring them again; it is included once per shader.
#include "gbuffer_layout.h"

uniform sampler2D u_gbuffer_position;  // KIT_GBUF_POSITION: world position, a = 1 where covered
uniform sampler2D u_gbuffer_normal;    // KIT_GBUF_NORMAL: world unit normal
uniform sampler2D u_gbuffer_albedo;    // KIT_GBUF_ALBEDO: linear base colour
uniform sampler2D u_gbuffer_material;  // KIT_GBUF_MATERIAL: metallic, roughness, 0 (unused), mask
uniform sampler2D u_gbuffer_emission;  // KIT_GBUF_EMISSION: emitted radiance L_e (linear RGB)
uniform sampler2D u_gbuffer_depth;     // depth texture, [0,1] window depth
uniform sampler2D u_hdr;               // linear HDR lighting result (stage 2 on)
uniform sampler2D u_bloom;             // blurred bright pass (stage 5)
uniform sampler2D u_ldr;               // tone-mapped image (stage 5 custom effect input)

#include "camera_uniforms.glsl"
uniform vec2 u_resolution;             // target size in pixels

uniform vec3 u_clear_color;            // linear HDR colour for pixels with mask 0
uniform float u_gamma;                 // display gamma for tonemap.glsl
// u_attenuation_model (0 physical, 1 simple) is declared in light_specialisation.glsl (lights.glsl
// includes it), beside the lights it applies to.
uniform float u_bloom_threshold;       // bright-pass luminance threshold
uniform bool u_postprocess_enabled;    // the P toggle
uniform bool u_custom_enabled;         // the free-choice effect's toggle
uniform bool u_horizontal;             // blur direction of this pass
uniform float u_time;                  // seconds, for animated effects (0 when headless)
