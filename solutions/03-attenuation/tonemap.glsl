// Reinhard tone mapping, then gamma (as in LearnOpenGL's HDR chapter).
#include "uniforms.glsl"

vec3 tonemap(vec3 hdr) {
    vec3 mapped = max(hdr, 0.0) / (max(hdr, 0.0) + 1.0);  // [0, inf) -> [0, 1)
    return pow(mapped, vec3(1.0 / u_gamma));
}
