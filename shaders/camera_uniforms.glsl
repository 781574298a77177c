// The camera, as the framework sets it for every pass. uniforms.glsl and
// geometry_uniforms.glsl both include it; a shader that includes both gets it once.
uniform mat4 u_view;                   // world -> camera
uniform mat4 u_projection;             // camera -> clip
uniform mat4 u_inv_view_projection;    // clip -> world
uniform vec3 u_camera_position;        // world space
uniform vec2 u_camera_near_far;        // near and far plane distances
