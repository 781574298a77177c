// Lab 7's light volumes: the framework draws the unit volume (a mesh enclosing the unit
// sphere, at KIT_ATTR_POSITION) once for every point and spot light, as instances. The
// directional lights come first in the light list and stay in the full-screen pass, so
// instance i is light u_volume_light_offset + i.
#include "lights.glsl"

uniform int u_volume_light_offset;

// The light this instance of the volume is drawn for (vertex shaders only).
int kit_volume_light_index() { return u_volume_light_offset + gl_InstanceID; }
