// glTF's alphaMode and doubleSided in the geometry pass's fragment stage: small
// helpers the framework gives the labs, because they are mechanics rather than
// the labs' subject (handouts/01-gbuffer.md, "Alpha modes and double-sided
// materials"). Fragment shaders only: they use discard and gl_FrontFacing.
#include "gbuffer_layout.h"
#include "material_uniforms.glsl"

// KIT_ALPHA_MASK: a fragment whose base colour alpha (factor * texel * COLOR_0) is below
// u_alpha_cutoff is not part of the surface. Discarding it leaves the G-buffer as
// cleared there (coverage mask 0) and writes no depth, so what lies behind shows.
// OPAQUE ignores alpha; BLEND is drawn like OPAQUE here, into the forward pass's
// layer G-buffer (common/render/forward_pass.h), which blends it by albedo.a.
// A program drawing no MASK material has no discard (KIT_HAS_ALPHA_MASK undefined,
// material_uniforms.glsl): llvmpipe then tests depth before the shader runs.
void kit_alpha_discard(float base_color_alpha) {
#ifdef KIT_HAS_ALPHA_MASK
    if (u_alpha_mode == KIT_ALPHA_MASK && base_color_alpha < u_alpha_cutoff) discard;
#endif
}

// A double-sided material is drawn without back-face culling; seen from behind,
// its normal points away from the viewer and every light in front would be
// below the surface. glTF: the back face's normal is reversed. gl_FrontFacing
// follows glFrontFace, which draw_scene sets for mirrored draws.
vec3 kit_facing_normal(vec3 n) {
    return u_double_sided && !gl_FrontFacing ? -n : n;
}
