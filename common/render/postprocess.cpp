// The passes after the lit frame (renderer.h): the display pass through tonemap.glsl, or
// stage 5's bloom (bright pass, separable blur, composite) and the custom effect.
#include "render/renderer_programs.h"

#include "gbuffer_layout.h"

namespace kit {

int blur_result(int passes) { return passes % 2 == 0 ? 0 : 1; }

void blur_ping_pong(const FullscreenTriangle& triangle, const Program& blur, const Texture2D (&targets)[2],
                    const Framebuffer (&fbos)[2], int passes, int width, int height) {
  for (int pass = 0; pass < passes; ++pass) {
    const bool horizontal = pass % 2 == 0;
    targets[horizontal ? 0 : 1].bind(KIT_UNIT_BLOOM);
    blur.set("u_horizontal", horizontal);
    triangle.pass(blur, fbos[horizontal ? 1 : 0], width, height);
  }
  targets[blur_result(passes)].bind(KIT_UNIT_BLOOM);
}

void Renderer::post_passes(PassClock& clock) {
  const Programs& p = *programs_;
  if (!stage_.postprocess) {
    // 3. Display: tone mapping and gamma (tonemap.glsl) -> LDR.
    set_frame_uniforms(p.display);
    fullscreen_pass(p.display, final_fbo_, settings_.width, settings_.height);
    check_gl("display pass");
    clock.lap("display");
    return;
  }

  // 3'. Bloom: bright pass, separable blur ping-pong, composite before tone mapping.
  set_frame_uniforms(p.bright);
  fullscreen_pass(p.bright, bloom_fbo_[0], settings_.width, settings_.height);
  set_frame_uniforms(p.blur);
  blur_ping_pong(triangle_, p.blur, bloom_, bloom_fbo_, settings_.blur_passes, settings_.width, settings_.height);
  hdr_.bind(KIT_UNIT_HDR);
  set_frame_uniforms(p.composite);
  fullscreen_pass(p.composite, composite_fbo_, settings_.width, settings_.height);
  composite_.bind(KIT_UNIT_LDR);
  set_frame_uniforms(p.custom);
  fullscreen_pass(p.custom, final_fbo_, settings_.width, settings_.height);
  check_gl("postprocess passes");
  clock.lap("postprocess");
}

}  // namespace kit
