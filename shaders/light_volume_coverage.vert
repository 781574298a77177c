#version 330 core
// The framework's own light volumes, for counting what they cover on screen (lab 7's
// work check, common/render/light_volumes.h): the unit volume at each light, scaled to
// its volume radius.
#include "uniforms.glsl"
#include "light_volumes.glsl"

layout(location = KIT_ATTR_POSITION) in vec3 a_position;

void main() {
    Light light = kit_light(kit_volume_light_index());
    gl_Position = u_projection * u_view * vec4(light.position + light.volume_radius * a_position, 1.0);
}
