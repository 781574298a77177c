#version 330 core
// Lab 7's evidence of where the volumes go wrong (common/render/light_volumes.h,
// VolumeEvidence): drawn with the student's light_volume.vert for one light at a time
// (u_volume_light_offset, one instance) inside an occlusion query, it lets a fragment
// through only where the framework's own geometry says so. Its colour writes are masked.
//   u_evidence_mode 0: the pixel's view ray meets the sphere enclosing the framework's
//                      volume (u_volume_circumradius x the light's volume radius), so the
//                      student's volume and the framework's cover it both;
//   u_evidence_mode 1: the pixel holds a surface within the light's volume radius: a pixel
//                      the light must shade once.
#include "uniforms.glsl"
#include "lights.glsl"

uniform int u_volume_light_offset;  // light_volumes.glsl's: the light measured (one instance)
uniform int u_evidence_mode;
uniform float u_volume_circumradius;  // the unit volume's farthest vertex (it encloses the unit sphere)
out vec4 out_color;

void main() {
    Light light = kit_light(u_volume_light_offset);
    if (u_evidence_mode == 0) {
        vec2 ndc = 2.0 * gl_FragCoord.xy / u_resolution - 1.0;
        vec4 near_point = u_inv_view_projection * vec4(ndc, -1.0, 1.0);
        vec4 far_point = u_inv_view_projection * vec4(ndc, 1.0, 1.0);
        vec3 origin = near_point.xyz / near_point.w;
        vec3 direction = normalize(far_point.xyz / far_point.w - origin);
        vec3 to_centre = light.position - origin;
        float along = dot(to_centre, direction);
        float radius = u_volume_circumradius * light.volume_radius;
        float miss2 = dot(to_centre, to_centre) - along * along;  // squared distance of the ray's line
        // A sphere behind the ray's start counts only where it holds the start (the camera inside).
        bool hit = miss2 <= radius * radius && (along >= 0.0 || dot(to_centre, to_centre) <= radius * radius);
        if (!hit) discard;
    } else {
        if (texelFetch(u_gbuffer_material, ivec2(gl_FragCoord.xy), 0).a < 0.5) discard;
        vec3 to_light = light.position - texelFetch(u_gbuffer_position, ivec2(gl_FragCoord.xy), 0).xyz;
        if (dot(to_light, to_light) > light.volume_radius * light.volume_radius) discard;
    }
    out_color = vec4(0.0);
}
