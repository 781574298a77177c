#version 330 core
// Light volumes: the framework draws the unit volume once for every point and spot light
// (instance gl_InstanceID of light kit_volume_light_index()). Place it around its light,
// scaled to the light's volume radius, so that it covers every pixel the light can reach.
#include "uniforms.glsl"
#include "light_volumes.glsl"

// The GL state the framework draws the volumes with (handouts/07-lightvolumes.md):
//   cull(none | back | front)                  the faces not drawn
//   depth(off | less_equal | greater_equal)    the test against the G-buffer's depth
//   blend(off | add)                           how each light's term meets the HDR target
// TODO: which faces, which depth test and which blend give every covered pixel exactly
// one fragment per light, also when the camera is inside a volume, and add the lights up?
#pragma kit_light_volume cull(back) depth(less_equal) blend(off)

layout(location = KIT_ATTR_POSITION) in vec3 a_position;  // the unit volume (encloses the unit sphere)

flat out int v_light;  // which light this volume shades

void main() {
    v_light = kit_volume_light_index();
    // TODO: the volume around its light (kit_light(v_light): position, volume_radius),
    // in world space, then to clip space.
    gl_Position = vec4(0.0);
}
