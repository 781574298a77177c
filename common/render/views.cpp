// The views of a frame (renderer.h): their names, and the Renderer's read-back of each as an
// image or as a texture to display, with the NaN/Inf counts taken from them.
#include "render/renderer_programs.h"

#include <algorithm>

#include "base/error.h"
#include "gbuffer_layout.h"
#include "render/ibl.h"

namespace kit {

namespace {

// Debug view modes understood by shaders/debug_view.frag.
int debug_mode(View view) {
  switch (view) {
    case View::Position: return 0;
    case View::Normal: return 1;
    case View::Albedo: return 2;
    case View::Material: return 3;
    case View::Depth: return 4;
    case View::Emission: return 5;
    default: return 2;
  }
}

}  // namespace

View parse_view(const std::string& name) {
  static const std::pair<const char*, View> names[] = {
      {"final", View::Final},       {"position", View::Position}, {"normal", View::Normal}, {"albedo", View::Albedo},
      {"material", View::Material}, {"emission", View::Emission}, {"depth", View::Depth},   {"hdr", View::Hdr},
      {"irradiance", View::Irradiance}, {"prefiltered", View::Prefiltered}, {"brdf-lut", View::BrdfLut}};
  for (const auto& [n, v] : names)
    if (name == n) return v;
  throw Error("unknown view '" + name +
              "' (views: final, position, normal, albedo, material, emission, depth, hdr, and at stage 6 "
              "irradiance, prefiltered, brdf-lut)");
}

const char* view_name(View view) {
  switch (view) {
    case View::Final: return "final";
    case View::Position: return "position";
    case View::Normal: return "normal";
    case View::Albedo: return "albedo";
    case View::Material: return "material";
    case View::Emission: return "emission";
    case View::Depth: return "depth";
    case View::Hdr: return "hdr";
    case View::Irradiance: return "irradiance";
    case View::Prefiltered: return "prefiltered";
    case View::BrdfLut: return "brdf-lut";
  }
  return "?";
}

bool is_precomputed_map(View view) {
  return view == View::Irradiance || view == View::Prefiltered || view == View::BrdfLut;
}

size_t Renderer::count_non_finite(View view) {
  if (view == View::Final && stage_.lighting) view = View::Hdr;
  return kit::count_non_finite(read_view(view, true));
}

std::vector<NonFiniteCount> Renderer::non_finite_pixels() {
  std::vector<NonFiniteCount> out;
  const size_t pixels = static_cast<size_t>(settings_.width) * static_cast<size_t>(settings_.height);
  for (View view : {View::Position, View::Normal, View::Material, View::Emission, View::Hdr}) {
    if (view == View::Hdr && !stage_.lighting) continue;
    out.push_back({view, count_non_finite(view), pixels});
  }
  return out;
}

const Texture2D& Renderer::final_texture() const {
  return stage_.lighting ? final_ : gbuffer_.attachment(KIT_GBUF_ALBEDO);
}

Image Renderer::read_view(View view, bool raw) {
  if (is_precomputed_map(view)) {
    if (!ibl_) throw Error(std::string("view '") + view_name(view) + "' needs stage 6 (ibl)");
    if (view == View::Irradiance) return read_texture(ibl_->irradiance());
    if (view == View::BrdfLut) return read_texture(ibl_->brdf_lut());
    return read_prefiltered_levels(ibl_->prefiltered());
  }
  if (raw && view != View::Final && view != View::Hdr) {
    if (view == View::Depth) return read_texture(gbuffer_.depth(), true);
    int index = view == View::Position ? KIT_GBUF_POSITION : view == View::Normal ? KIT_GBUF_NORMAL
              : view == View::Albedo ? KIT_GBUF_ALBEDO : view == View::Emission ? KIT_GBUF_EMISSION : KIT_GBUF_MATERIAL;
    return read_texture(gbuffer_.attachment(index));
  }
  return read_texture(display_texture(view));
}

const Texture2D& Renderer::display_texture(View view) {
  if (view == View::Final) return final_texture();
  if (is_precomputed_map(view)) {
    if (!ibl_) throw Error(std::string("view '") + view_name(view) + "' needs stage 6 (ibl)");
    return view == View::Irradiance ? ibl_->irradiance() : view == View::BrdfLut ? ibl_->brdf_lut() : ibl_->prefiltered();
  }
  if (view == View::Hdr) {
    if (!stage_.lighting) throw Error("view 'hdr' needs a lit stage (lighting or later)");
    return hdr_;
  }
  // Display mapping in shaders/debug_view.frag.
  gbuffer_.bind_textures();
  const Program& d = programs_->debug;
  set_frame_uniforms(d);
  d.set("u_view_mode", debug_mode(view));
  glm::vec3 center = 0.5f * (scene_.bounds_min + scene_.bounds_max);
  glm::vec3 half = glm::max(0.5f * (scene_.bounds_max - scene_.bounds_min), glm::vec3(1e-3f));
  d.set("u_position_center", center);
  d.set("u_position_half_extent", half);
  float far_display = 0.0f;
  for (int c = 0; c < 8; ++c) {
    glm::vec3 corner((c & 1) ? scene_.bounds_max.x : scene_.bounds_min.x, (c & 2) ? scene_.bounds_max.y : scene_.bounds_min.y,
                     (c & 4) ? scene_.bounds_max.z : scene_.bounds_min.z);
    far_display = std::max(far_display, glm::length(corner - camera_.position));
  }
  d.set("u_depth_display_far", std::min(far_display, camera_.zfar));
  fullscreen_pass(d, debug_fbo_, settings_.width, settings_.height);
  check_gl("debug view");
  return debug_target_;
}

}  // namespace kit
