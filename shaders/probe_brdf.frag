#version 330 core
// The grader's probes of lab 2's functions, written by tools/grade/lab_contract.py from
// the lab's contract, tools/grade/lab_functions.json (edit that, not this): fragment x
// writes the value of function u_probe_function (its place in the lab's list) at case x.
// Each call stands between #if lines of its own, so a file that lacks one function still
// has the others probed.
#include "function_probe_inputs.glsl"
#include "brdf.glsl"

out vec4 o_value;

void main() {
    int at = 0;
    o_value = vec4(0.0);
#if defined(KIT_PROBE_FRESNEL_SCHLICK)
    if (u_probe_function == 0) {
        float v_dot_h = kit_probe_float(at);
        vec3 f0 = kit_probe_vec3(at);
        o_value.rgb = fresnel_schlick(v_dot_h, f0);
    }
#endif
#if defined(KIT_PROBE_DISTRIBUTION_GGX)
    if (u_probe_function == 1) {
        float n_dot_h = kit_probe_float(at);
        float alpha = kit_probe_float(at);
        o_value.r = distribution_ggx(n_dot_h, alpha);
    }
#endif
#if defined(KIT_PROBE_MICROFACET_GEOMETRY)
    if (u_probe_function == 2) {
        float n_dot_h = kit_probe_float(at);
        float n_dot_v = kit_probe_float(at);
        float n_dot_l = kit_probe_float(at);
        float v_dot_h = kit_probe_float(at);
        float roughness = kit_probe_float(at);
        o_value.r = microfacet_geometry(n_dot_h, n_dot_v, n_dot_l, v_dot_h, roughness);
    }
#endif
#if defined(KIT_PROBE_COOK_TORRANCE)
    if (u_probe_function == 3) {
        vec3 n = kit_probe_vec3(at);
        vec3 v = kit_probe_vec3(at);
        vec3 l = kit_probe_vec3(at);
        vec3 albedo = kit_probe_vec3(at);
        float metallic = kit_probe_float(at);
        float perceptual_roughness = kit_probe_float(at);
        o_value.rgb = cook_torrance(n, v, l, albedo, metallic, perceptual_roughness);
    }
#endif
}
