// The inputs of the grader's function probes (tools/grade/frames/function_probes.h): case x of a
// probe is column x of u_probe_inputs, its arguments' floats one after another down the
// column, four to a texel. The probe shaders read each argument in order with the
// functions below and write the function's value: they call a lab's functions and hold
// none of their formulas.
#include "lights.glsl"

uniform sampler2D u_probe_inputs;  // RGBA32F, one column per case
uniform int u_probe_function;      // which function of the probe shader (its table's index)

float kit_probe_float(inout int at) {
    vec4 texel = texelFetch(u_probe_inputs, ivec2(int(gl_FragCoord.x), at / 4), 0);
    float value = texel[at % 4];
    at += 1;
    return value;
}

// Read one component at a time: the order a constructor's arguments are evaluated in is
// not something to lean on.
vec3 kit_probe_vec3(inout int at) {
    vec3 v;
    v.x = kit_probe_float(at);
    v.y = kit_probe_float(at);
    v.z = kit_probe_float(at);
    return v;
}

// A Light in the order of its struct (lights.glsl), the type as a float.
Light kit_probe_light(inout int at) {
    Light light;
    light.type = int(kit_probe_float(at) + 0.5);
    light.position = kit_probe_vec3(at);
    light.direction = kit_probe_vec3(at);
    light.range = kit_probe_float(at);
    light.color = kit_probe_vec3(at);
    light.intensity = kit_probe_float(at);
    light.cos_inner = kit_probe_float(at);
    light.cos_outer = kit_probe_float(at);
    light.flux = kit_probe_float(at);
    light.volume_radius = kit_probe_float(at);
    return light;
}
