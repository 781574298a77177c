// Where a light's contribution falls below epsilon: the radius of its volume (light
// volumes) and of its culling sphere (tiled deferred).
//
// Bound: outgoing radiance from one light is f L_i (n.l) with n.l <= 1, the spot
// cone factor <= 1 and L_i <= I c_max / r^2 (I the glTF intensity in candela: the
// physical model's flux / (4 pi r^2) is exactly I / r^2 for a point light and at
// most that for a spot). For f the bound is the Lambertian lobe at albedo 1, 1/pi.
// Setting I c_max / (pi r^2) = epsilon gives r = sqrt(I c_max / (pi epsilon)); with
// seed 002's simple model I / (1 + r^2) the same bound gives r^2 = I c_max/(pi epsilon) - 1.
// The bound ignores the specular lobe: a glossy highlight of a light outside its
// volume is lost (kit-bench measures what that costs).
#include "lights.glsl"
#include "math.glsl"
#include "uniforms.glsl"

uniform float u_light_epsilon;  // linear HDR radiance a light may still add outside its volume
// Counting mode (kit-bench's lights-per-pixel figure): each light that passes the
// radius test adds 1 instead of its radiance.
uniform bool u_count_lights;

float light_cutoff_radius(Light light) {
    float c_max = max(light.color.r, max(light.color.g, light.color.b));
    float r2 = light.intensity * c_max / (KIT_PI * u_light_epsilon);
    if (u_attenuation_model == 1) r2 -= 1.0;
    return sqrt(max(r2, 0.0));
}
