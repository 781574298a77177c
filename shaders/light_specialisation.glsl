// What the renderer compiles into the lighting shaders as constants when the frame allows
// it (renderer.h: apply_attenuation_model_define, LightBuffers::apply_defines), each
// with the general form beside it. Why: llvmpipe runs both sides of every branch and reads
// every light field it names, so code and fields no light of the frame needs still cost.
// The grader compiles the general forms alone (one program for all its scenes; renderer.h,
// RenderSettings::specialise_shaders): the values are the same either way.
// Only lights.glsl includes it: the shaders that light are the ones rebuilt when a define changes.
#include "gbuffer_layout.h"

// Lab 3's falloff: 0 physical (the lecture's inverse square), 1 simple 1/(1+d^2).
#if defined(KIT_ATTENUATION_MODEL_PHYSICAL)
const int u_attenuation_model = 0;
#elif defined(KIT_ATTENUATION_MODEL_SIMPLE)
const int u_attenuation_model = 1;
#else
uniform int u_attenuation_model;
#endif

// A light's type: the frame's one type when every light has it, else its own (t0.w of its row).
int kit_light_type(vec4 t0) {
#if defined(KIT_LIGHTS_ALL_POINT)
    return KIT_LIGHT_POINT;
#elif defined(KIT_LIGHTS_ALL_SPOT)
    return KIT_LIGHT_SPOT;
#elif defined(KIT_LIGHTS_ALL_DIRECTIONAL)
    return KIT_LIGHT_DIRECTIONAL;
#else
    return int(t0.w + 0.5);
#endif
}

// A light's glTF range: 0 (unlimited) when no light of the frame has one, else its own (t1.w).
float kit_light_range(vec4 t1) {
#ifdef KIT_LIGHTS_WITHOUT_RANGE
    return 0.0;
#else
    return t1.w;
#endif
}
