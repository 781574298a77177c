#version 330 core
// Light volumes: instance i is light i's proxy sphere, scaled to the radius where
// its contribution falls below the method's epsilon (light_bounds.glsl).
#include "gbuffer_layout.h"
#include "lights.glsl"
#include "light_bounds.glsl"

uniform mat4 u_view_projection;

// Vertices of a mesh that encloses the unit sphere (instructor/bench/bench_renderer.cpp scales
// the polyhedron so that every face lies outside it), so the scaled mesh covers
// every pixel the true sphere covers.
layout(location = KIT_ATTR_POSITION) in vec3 a_position;

// The light, fetched once per vertex rather than once per fragment.
flat out Light v_light;
flat out float v_radius;

void main() {
    LightBound bound = light_bound(gl_InstanceID);
    v_light = kit_light(gl_InstanceID);
    v_radius = bound.radius;
    gl_Position = u_view_projection * vec4(bound.center + a_position * bound.radius, 1.0);
}
