#version 330 core
// Light volumes: the framework draws the unit volume once for every point and spot light
// (instance gl_InstanceID of light kit_volume_light_index()). Place it around its light,
// scaled to the light's volume radius, so that it covers every pixel the light can reach.
#include "uniforms.glsl"
#include "light_volumes.glsl"

// The GL state the framework draws the volumes with (handouts/07-lightvolumes.md).
// Back faces only (front faces culled): every pixel a volume covers gets exactly one
// fragment, in front of the camera also when the camera is inside the volume. The test
// greater_equal against the G-buffer's depth passes where the surface lies in front of the
// volume's far side, so surfaces behind the whole volume are never shaded. Each light's
// term is added to what the full-screen pass wrote.
#pragma kit_light_volume cull(front) depth(greater_equal) blend(add)

layout(location = KIT_ATTR_POSITION) in vec3 a_position;  // the unit volume (encloses the unit sphere)

flat out int v_light;  // which light this volume shades

void main() {
    v_light = kit_volume_light_index();
    Light light = kit_light(v_light);
    vec3 world = light.position + light.volume_radius * a_position;
    gl_Position = u_projection * u_view * vec4(world, 1.0);
}
