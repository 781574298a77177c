#version 330 core
// Forward shading baseline: the scene drawn once, every fragment that passes the
// depth test lit by every light (overdrawn fragments are shaded and then hidden).
// Same material evaluation, BRDF and falloff as the deferred methods.
#include "surface_inputs.glsl"
#include "shade.glsl"

out vec4 out_color;

void main() {
    SurfaceInputs m = surface_inputs();
    Surface s;
    s.covered = true;
    s.position = v_world_position - u_shading_origin;
    s.normal = m.normal;
    s.albedo = m.albedo;
    s.metallic = m.metallic;
    s.roughness = m.roughness;
    s.emission = m.emission;
    out_color = vec4(shade_all(s, u_light_count), 1.0);
}
