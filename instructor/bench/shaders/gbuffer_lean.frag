#version 330 core
// Geometry pass into the lean G-buffer (bench_layout.h): no position (the lighting
// pass reconstructs it from depth), an octahedral normal, a packed RGBA8 material,
// the emitted radiance encoded in RGBA8.
#include "bench_layout.h"
#include "surface_inputs.glsl"
#include "lean_encoding.glsl"

layout(location = KIT_LEAN_NORMAL) out vec2 out_normal;
layout(location = KIT_LEAN_ALBEDO) out vec4 out_albedo;
layout(location = KIT_LEAN_MATERIAL) out vec4 out_material;
layout(location = KIT_LEAN_EMISSION) out vec4 out_emission;

void main() {
    SurfaceInputs m = surface_inputs();
    out_normal = oct_encode(m.normal);
    out_albedo = vec4(m.albedo, m.alpha);
    out_material = vec4(m.metallic, m.roughness, 0.0, 1.0);
    out_emission = vec4(emission_encode(m.emission), 0.0);
}
