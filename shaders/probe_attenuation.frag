#version 330 core
// The grader's probes of lab 3's functions, written by tools/grade/lab_contract.py from
// the lab's contract, tools/grade/lab_functions.json (edit that, not this): fragment x
// writes the value of function u_probe_function (its place in the lab's list) at case x.
// Each call stands between #if lines of its own, so a file that lacks one function still
// has the others probed.
#include "function_probe_inputs.glsl"
#include "attenuation.glsl"
#include "tonemap.glsl"

out vec4 o_value;

void main() {
    int at = 0;
    o_value = vec4(0.0);
#if defined(KIT_PROBE_SPOT_CONE_FACTOR)
    if (u_probe_function == 0) {
        Light light = kit_probe_light(at);
        vec3 p = kit_probe_vec3(at);
        o_value.r = spot_cone_factor(light, p);
    }
#endif
#if defined(KIT_PROBE_LIGHT_RADIANCE)
    if (u_probe_function == 1) {
        Light light = kit_probe_light(at);
        vec3 p = kit_probe_vec3(at);
        o_value.rgb = light_radiance(light, p);
    }
#endif
#if defined(KIT_PROBE_TONEMAP)
    if (u_probe_function == 2) {
        vec3 hdr = kit_probe_vec3(at);
        o_value.rgb = tonemap(hdr);
    }
#endif
}
