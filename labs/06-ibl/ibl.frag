#version 330 core
// Lab 6 - the image-based lighting pass. See handouts/06-ibl.md.
#include "uniforms.glsl"
#include "environment.glsl"
#include "guards.glsl"
#include "brdf.glsl"

in vec2 v_uv;
out vec4 out_color;

void main() {
    vec4 material = texture(u_gbuffer_material, v_uv);
    // TODO(lab 6): where the coverage mask (material.a) is 0, add nothing: the
    //              framework draws the environment there.

    // TODO(lab 6): the environment's light reflected towards the camera, by the
    //              split sum, with F0 as in lab 2's cook_torrance:
    //              specular = (F0 A + B) * kit_prefiltered_radiance(reflect(-v, n), roughness)
    //              diffuse  = (1 - metallic) * albedo * (1 - F0) * C * kit_irradiance(n) / pi
    //              where (A, B, C) = kit_brdf_lut(n.v, roughness).
    out_color = vec4(0.0);  // placeholder: the environment adds nothing yet
}
