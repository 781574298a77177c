#version 330 core
// A light marker (common/render/forward_pass.h): the enclosing-sphere mesh, scaled to
// u_marker_radius and moved to the light's position.
#include "gbuffer_layout.h"

layout(location = KIT_ATTR_POSITION) in vec3 a_position;

uniform mat4 u_view_projection;
uniform vec3 u_marker_center;  // world space
uniform float u_marker_radius; // world units

void main() {
    gl_Position = u_view_projection * vec4(u_marker_center + u_marker_radius * a_position, 1.0);
}
