// Lab 3 - tone mapping and gamma. See handouts/03-attenuation.md.
#include "uniforms.glsl"

vec3 tonemap(vec3 hdr) {
    // TODO(lab 3): Reinhard c / (c + 1), then pow(c, 1 / u_gamma).
    return clamp(hdr, 0.0, 1.0);
}
