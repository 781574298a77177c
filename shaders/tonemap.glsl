// Stage 2's display mapping: HDR clamped to [0,1]. Lab 3 replaces this file
// with Reinhard tone mapping and gamma.
#include "uniforms.glsl"

vec3 tonemap(vec3 hdr) {
    return clamp(hdr, 0.0, 1.0);
}
