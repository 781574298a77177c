// The lighting pass (from stage 2) and stage 7's light volume pass, with the counts that
// measure the volumes' work (light_volumes.h).
#include "render/renderer_programs.h"

#include <algorithm>
#include <cstdint>
#include <vector>

#include "gbuffer_layout.h"
#include "gl/gl_flavour.h"
#include "render/forward_pass.h"
#include "render/light_volumes.h"

namespace kit {

bool skips_background_pixels(const Stage& stage) {
  return stage.lighting && std::find(stage.files.begin(), stage.files.end(), "lighting.frag") == stage.files.end();
}

void Renderer::lighting_pass(const Program& lighting) const {
  if (!skips_background_pixels(stage_)) {
    fullscreen_pass(lighting, hdr_fbo_, settings_.width, settings_.height);
    return;
  }
  // What lighting.frag writes where its coverage mask is 0, given before the pass.
  lighting_fbo_.bind();
  glClearColor(settings_.clear_color.r, settings_.clear_color.g, settings_.clear_color.b, 1.0f);
  glClear(GL_COLOR_BUFFER_BIT);
  triangle_.pass_over_surfaces(lighting, lighting_fbo_, settings_.width, settings_.height);
}

namespace {

// Draws `instances` volumes of `sphere` with `program` (in use, uniforms set) under
// `state`, into the bound target; `colour` false writes no colour (counting draws). GL's
// defaults are restored after. Depth clamping keeps a volume that reaches past the far
// plane: its faces there are clamped to depth 1, where the depth test still decides.
void draw_light_volumes(const Mesh& sphere, int instances, const LightVolumeState& state, bool colour) {
  glDepthMask(GL_FALSE);
  if (state.depth == LightVolumeState::Depth::Off) {
    glDisable(GL_DEPTH_TEST);
  } else {
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(state.depth == LightVolumeState::Depth::LessEqual ? GL_LEQUAL : GL_GEQUAL);
  }
  if (state.cull == LightVolumeState::Cull::None) {
    glDisable(GL_CULL_FACE);
  } else {
    glEnable(GL_CULL_FACE);
    glCullFace(state.cull == LightVolumeState::Cull::Back ? GL_BACK : GL_FRONT);
  }
  if (colour && state.blend_add) {
    glEnable(GL_BLEND);
    glBlendFunc(GL_ONE, GL_ONE);
  } else {
    glDisable(GL_BLEND);
  }
  if (!colour) glColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
  set_depth_clamp(true);
  sphere.draw_instanced(instances);
  set_depth_clamp(false);
  glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
  glDisable(GL_BLEND);
  glDisable(GL_CULL_FACE);
  glCullFace(GL_BACK);
  glDisable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  glDepthMask(GL_TRUE);
}

// The samples `draw` lets through (GL_SAMPLES_PASSED: one per pixel here, exact; in
// WebGL2 only whether any did, gl_flavour.h).
template <typename Draw>
uint64_t samples_passed(Draw draw) {
  GLuint query = 0;
  glGenQueries(1, &query);
  begin_samples_passed(query);
  draw();
  end_samples_passed();
  const uint64_t samples = samples_passed_result(query);
  glDeleteQueries(1, &query);
  return samples;
}

}  // namespace

void Renderer::light_volume_pass() {
  const Programs& p = *programs_;
  const int volumes = light_count_ - directional_count_;
  volume_work_ = LightVolumeWork{};
  volume_work_.volume_lights = volumes;
  if (volumes <= 0) return;
  if (volume_sphere_.index_count() == 0) volume_sphere_ = enclosing_sphere_mesh(kLightVolumeSubdivisions);
  lighting_fbo_.bind();  // the HDR target with the G-buffer's depth
  glViewport(0, 0, settings_.width, settings_.height);
  auto set_uniforms = [&](const Program& program) {
    set_frame_uniforms(program);
    program.set("u_volume_light_offset", directional_count_);
  };
  set_uniforms(p.volume);
  draw_light_volumes(volume_sphere_, volumes, volume_state_, true);
  if (!settings_.count_light_volume_work) return;
  // The same volumes under the same state, through a fragment shader that writes
  // nothing: every fragment the student's fragment shader was run for.
  set_uniforms(p.volume_count);
  volume_work_.shaded_fragments =
      samples_passed([&] { draw_light_volumes(volume_sphere_, volumes, volume_state_, false); });
  // The framework's own spheres under the state that does least: back faces only (each
  // pixel once, also with the camera inside), depth greater_equal (only where the surface
  // lies in front of the sphere's far side). What a state shades beyond it is work outside
  // the light's sphere in depth: surfaces behind it (no depth test), or a second fragment
  // where the surface lies in front of it (both faces drawn).
  set_uniforms(p.volume_coverage);
  LightVolumeState coverage;
  coverage.cull = LightVolumeState::Cull::Front;
  coverage.depth = LightVolumeState::Depth::GreaterEqual;
  volume_work_.volume_coverage = samples_passed([&] { draw_light_volumes(volume_sphere_, volumes, coverage, false); });
  // The pixels the full-screen loop shades: those with a surface.
  set_frame_uniforms(p.surface_count);
  volume_work_.surface_pixels = samples_passed([&] {
    glColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
    triangle_.pass_over_surfaces(p.surface_count, lighting_fbo_, settings_.width, settings_.height);
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
  });
  if (samples_passed_counts()) measure_volume_evidence();
}

void Renderer::measure_volume_evidence() {
  const Programs& p = *programs_;
  const int volumes = light_count_ - directional_count_;
  VolumeEvidence& e = volume_work_.evidence;
  e = VolumeEvidence{};
  e.adds = volume_state_.blend_add;
  // The framework's counting state: back faces only, no depth test, so a closed volume
  // gives each pixel it covers one fragment, also with the camera inside it.
  LightVolumeState once;
  once.cull = LightVolumeState::Cull::Front;
  once.depth = LightVolumeState::Depth::Off;
  // One light's volume alone: instance 0 of the draw is light u_volume_light_offset.
  enum Count { kFootprint, kOverlap, kStudentFootprint, kMustShade, kShaded, kCounts };
  const int measured = std::min(volumes, kEvidenceLights);
  std::vector<GLuint> queries(static_cast<size_t>(measured) * kCounts);
  glGenQueries(static_cast<GLsizei>(queries.size()), queries.data());
  std::vector<int> number(static_cast<size_t>(measured));  // each measured light's in the scene's list
  static const float circumradius = enclosing_sphere_circumradius(kLightVolumeSubdivisions);
  for (int m = 0; m < measured; ++m) {
    // Evenly spread over the volume lights, the first and the last included.
    const int i = measured == 1 ? 0 : static_cast<int>((static_cast<int64_t>(m) * (volumes - 1)) / (measured - 1));
    const int light = directional_count_ + i;
    number[static_cast<size_t>(m)] = frame_light_numbers_[static_cast<size_t>(light)];
    auto count = [&](Count which, const Program& program, const LightVolumeState& state, int mode) {
      set_frame_uniforms(program);
      program.set("u_volume_light_offset", light);
      if (mode >= 0) {
        program.set("u_evidence_mode", mode);
        program.set("u_volume_circumradius", circumradius);
      }
      begin_samples_passed(queries[static_cast<size_t>(m) * kCounts + which]);
      draw_light_volumes(volume_sphere_, 1, state, false);
      end_samples_passed();
    };
    count(kFootprint, p.volume_coverage, once, -1);
    count(kOverlap, p.volume_evidence, once, 0);
    count(kStudentFootprint, p.volume_count, once, -1);
    // The state alone, on the framework's volume: does it give each surface pixel inside the
    // light's sphere one fragment?
    count(kMustShade, p.state_evidence, once, 1);
    count(kShaded, p.state_evidence, volume_state_, 1);
  }
  // Read once all are drawn: one wait for the queries, not one per light.
  uint64_t worst_volume = 0, worst_state = 0;
  for (int m = 0; m < measured; ++m) {
    uint64_t c[kCounts];
    for (int k = 0; k < kCounts; ++k) c[k] = samples_passed_result(queries[static_cast<size_t>(m) * kCounts + k]);
    // The framework's footprint is the enclosing sphere's less a sliver: overlap may exceed it.
    const uint64_t missing = c[kFootprint] > c[kOverlap] ? c[kFootprint] - c[kOverlap] : 0;
    const uint64_t extra = c[kStudentFootprint] > c[kOverlap] ? c[kStudentFootprint] - c[kOverlap] : 0;
    const uint64_t state_off = c[kShaded] > c[kMustShade] ? c[kShaded] - c[kMustShade] : c[kMustShade] - c[kShaded];
    e.lights += 1;
    e.footprint += c[kFootprint];
    e.missing += missing;
    e.extra += extra;
    e.must_shade += c[kMustShade];
    e.shaded_wrong += state_off;
    if (missing + extra > worst_volume) {
      worst_volume = missing + extra;
      e.worst_volume_light = number[static_cast<size_t>(m)];
      e.worst_footprint = c[kFootprint];
      e.worst_missing = missing;
      e.worst_extra = extra;
    }
    if (state_off > worst_state) {
      worst_state = state_off;
      e.worst_state_light = number[static_cast<size_t>(m)];
      e.worst_must_shade = c[kMustShade];
      e.worst_shaded = c[kShaded];
    }
  }
  glDeleteQueries(static_cast<GLsizei>(queries.size()), queries.data());
}

}  // namespace kit
