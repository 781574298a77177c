#include "render/forward_pass.h"

#include <algorithm>
#include <cmath>
#include <map>

#include "base/error.h"
#include "gbuffer_layout.h"
#include "render/renderer.h"

namespace kit {

namespace {
// The forward pass's two programs.
constexpr const char* kBlendVertex = "fullscreen.vert";
constexpr const char* kBlendFragment = "blend_layer.frag";
constexpr const char* kMarkerVertex = "light_marker.vert";
constexpr const char* kMarkerFragment = "light_marker.frag";

glm::vec3 box_corner(const glm::vec3& lo, const glm::vec3& hi, int c) {
  return {(c & 1) ? hi.x : lo.x, (c & 2) ? hi.y : lo.y, (c & 4) ? hi.z : lo.z};
}
}  // namespace

bool is_blend_draw(const Scene& scene, const DrawItem& draw) {
  return draw_material(scene, draw).alpha_mode == KIT_ALPHA_BLEND;
}

bool has_blend_draws(const Scene& scene) {
  return std::any_of(scene.draws.begin(), scene.draws.end(), [&](const DrawItem& d) { return is_blend_draw(scene, d); });
}

std::vector<size_t> blend_draws_back_to_front(const Scene& scene, const glm::mat4& view) {
  std::vector<std::pair<float, size_t>> keyed;  // (view-space depth of the bounds' centre, draw)
  for (size_t i = 0; i < scene.draws.size(); ++i) {
    const DrawItem& d = scene.draws[i];
    if (!is_blend_draw(scene, d)) continue;
    const Primitive& prim = scene.primitives[static_cast<size_t>(d.primitive)];
    glm::vec3 lo(INFINITY), hi(-INFINITY);
    for (int c = 0; c < 8; ++c) {
      const glm::vec3 p = glm::vec3(d.world * glm::vec4(box_corner(prim.bounds_min, prim.bounds_max, c), 1.0f));
      lo = glm::min(lo, p);
      hi = glm::max(hi, p);
    }
    const glm::vec4 centre = view * glm::vec4(0.5f * (lo + hi), 1.0f);
    keyed.emplace_back(-centre.z, i);  // the camera looks down -z: larger -z is farther
  }
  std::stable_sort(keyed.begin(), keyed.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
  std::vector<size_t> out;
  for (const auto& k : keyed) out.push_back(k.second);
  return out;
}

std::optional<PixelRect> projected_rect(const glm::vec3& bounds_min, const glm::vec3& bounds_max, const glm::mat4& world,
                                        const glm::mat4& view_projection, int width, int height) {
  glm::vec2 lo(INFINITY), hi(-INFINITY);
  for (int c = 0; c < 8; ++c) {
    const glm::vec4 clip = view_projection * world * glm::vec4(box_corner(bounds_min, bounds_max, c), 1.0f);
    // Behind (or on) the camera's plane the projection wraps around: no bound from it.
    if (!(clip.w > 1e-6f)) return std::nullopt;
    const glm::vec2 ndc = glm::vec2(clip) / clip.w;
    lo = glm::min(lo, ndc);
    hi = glm::max(hi, ndc);
  }
  // NDC to pixels, widened by a pixel for rasterisation at the rect's edge.
  const auto to_pixels = [](float ndc, int size) { return (ndc * 0.5f + 0.5f) * static_cast<float>(size); };
  const int x0 = std::clamp(static_cast<int>(std::floor(to_pixels(lo.x, width))) - 1, 0, width);
  const int y0 = std::clamp(static_cast<int>(std::floor(to_pixels(lo.y, height))) - 1, 0, height);
  const int x1 = std::clamp(static_cast<int>(std::ceil(to_pixels(hi.x, width))) + 1, 0, width);
  const int y1 = std::clamp(static_cast<int>(std::ceil(to_pixels(hi.y, height))) + 1, 0, height);
  return PixelRect{x0, y0, std::max(x1 - x0, 0), std::max(y1 - y0, 0)};
}

namespace {

// The subdivided icosahedron's unit vertices and faces, and the distance of its nearest face
// plane from the centre (what enclosing_sphere_mesh scales by).
struct Icosphere {
  std::vector<glm::vec3> vertices;
  std::vector<glm::uvec3> faces;
  float nearest_plane = 1.0f;
};

Icosphere icosphere(int subdivisions) {
  const float t = (1.0f + std::sqrt(5.0f)) / 2.0f;
  std::vector<glm::vec3> v = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0}, {0, -1, t}, {0, 1, t},
                              {0, -1, -t}, {0, 1, -t}, {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
  std::vector<glm::uvec3> f = {{0, 11, 5}, {0, 5, 1}, {0, 1, 7}, {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
                               {11, 10, 2}, {10, 7, 6}, {7, 1, 8}, {3, 9, 4}, {3, 4, 2}, {3, 2, 6}, {3, 6, 8},
                               {3, 8, 9}, {4, 9, 5}, {2, 4, 11}, {6, 2, 10}, {8, 6, 7}, {9, 8, 1}};
  for (glm::vec3& p : v) p = glm::normalize(p);
  for (int s = 0; s < subdivisions; ++s) {
    std::map<std::pair<uint32_t, uint32_t>, uint32_t> midpoints;
    auto midpoint = [&](uint32_t a, uint32_t b) {
      auto key = std::minmax(a, b);
      auto it = midpoints.find(key);
      if (it != midpoints.end()) return it->second;
      v.push_back(glm::normalize(v[a] + v[b]));
      return midpoints[key] = static_cast<uint32_t>(v.size() - 1);
    };
    std::vector<glm::uvec3> finer;
    for (const glm::uvec3& tri : f) {
      uint32_t ab = midpoint(tri.x, tri.y), bc = midpoint(tri.y, tri.z), ca = midpoint(tri.z, tri.x);
      finer.insert(finer.end(), {{tri.x, ab, ca}, {tri.y, bc, ab}, {tri.z, ca, bc}, {ab, bc, ca}});
    }
    f = std::move(finer);
  }
  float nearest_plane = 1.0f;
  for (const glm::uvec3& tri : f) {
    glm::vec3 n = glm::normalize(glm::cross(v[tri.y] - v[tri.x], v[tri.z] - v[tri.x]));
    nearest_plane = std::min(nearest_plane, std::fabs(glm::dot(n, v[tri.x])));
  }
  return {std::move(v), std::move(f), nearest_plane};
}

}  // namespace

Mesh enclosing_sphere_mesh(int subdivisions) {
  const Icosphere ico = icosphere(subdivisions);
  std::vector<Vertex> vertices;
  for (const glm::vec3& p : ico.vertices)
    vertices.push_back({p / ico.nearest_plane, p, glm::vec2(0.0f), glm::vec2(0.0f), glm::vec4(1, 0, 0, 1)});
  std::vector<uint32_t> indices;
  for (const glm::uvec3& tri : ico.faces) indices.insert(indices.end(), {tri.x, tri.y, tri.z});  // CCW seen from outside
  return Mesh(vertices, indices);
}

float enclosing_sphere_circumradius(int subdivisions) { return 1.0f / icosphere(subdivisions).nearest_plane; }

float light_marker_radius(const Scene& scene) {
  return std::max(0.005f * glm::length(scene.bounds_max - scene.bounds_min), 1e-4f);
}

glm::vec3 light_marker_radiance(const Light& light) {
  const float brightest = std::max({light.color.r, light.color.g, light.color.b});
  // A black light (colour 0) still shows where it is, in grey.
  if (!(brightest > 0.0f)) return glm::vec3(0.25f * kMarkerRadiance);
  return light.color * (kMarkerRadiance / brightest);
}

ForwardPass::ForwardPass(const ShaderLibrary& library, int width, int height)
    : width_(width),
      height_(height),
      layer_(width, height),
      blend_(make_program(library, kBlendVertex, kBlendFragment)),
      marker_(make_program(library, kMarkerVertex, kMarkerFragment)),
      marker_sphere_(enclosing_sphere_mesh(1)) {
  allocate();
}

bool ForwardPass::built_from(const ShaderLibrary& library) const {
  return blend_.built_from(library, kBlendVertex, kBlendFragment) &&
         marker_.built_from(library, kMarkerVertex, kMarkerFragment);
}

void ForwardPass::allocate() {
  layer_hdr_ = Texture2D(width_, height_, {GL_RGBA16F, GL_RGBA, GL_FLOAT});
  layer_hdr_fbo_.attach_color(0, layer_hdr_);
  layer_hdr_fbo_.set_draw_buffers(1);
  std::string reason = layer_hdr_fbo_.incomplete_reason();
  if (!reason.empty()) throw Error("forward pass layer target incomplete: " + reason);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
}

void ForwardPass::resize(int width, int height) {
  if (width == width_ && height == height_) return;
  width_ = width;
  height_ = height;
  layer_.resize(width, height);
  allocate();
}

void ForwardPass::draw_blend_layers(const GeometryPrograms& geometry_programs, const Program& lighting,
                                    const Program* ibl, const Scene& scene, const SceneGpu& gpu, const GBuffer& opaque,
                                    const Framebuffer& hdr_fbo, const glm::mat4& view,
                                    const glm::mat4& view_projection, const FullscreenTriangle& triangle,
                                    std::vector<const Program*>* drawn) {
  for (size_t index : blend_draws_back_to_front(scene, view)) {
    const DrawItem& d = scene.draws[index];
    const Primitive& prim = scene.primitives[static_cast<size_t>(d.primitive)];
    const PixelRect rect = projected_rect(prim.bounds_min, prim.bounds_max, d.world, view_projection, width_, height_)
                               .value_or(PixelRect{0, 0, width_, height_});
    if (rect.width == 0 || rect.height == 0) continue;  // outside the view
    // Every step below touches only the draw's pixels.
    glEnable(GL_SCISSOR_TEST);
    glScissor(rect.x, rect.y, rect.width, rect.height);

    // 1. The layer's depth starts as the opaque surfaces' depth, so the layer is
    //    depth-tested against them; its colour attachments start as "no surface".
    glBindFramebuffer(GL_READ_FRAMEBUFFER, opaque.framebuffer().id());
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, layer_.framebuffer().id());
    const int x1 = rect.x + rect.width, y1 = rect.y + rect.height;
    glBlitFramebuffer(rect.x, rect.y, x1, y1, rect.x, rect.y, x1, y1, GL_DEPTH_BUFFER_BIT, GL_NEAREST);
    begin_geometry_pass_on(layer_.framebuffer(), width_, height_, glm::vec4(0.0f), false);
    const Program& geometry = geometry_programs.for_draw(scene, d);
    note_drawn(drawn, geometry);
    geometry.use();
    draw_item(geometry, scene, gpu, d);
    end_scene_draws();

    // 2. The stage's own lighting pass on the layer.
    layer_.bind_textures();
    triangle.pass(lighting, layer_hdr_fbo_, width_, height_);
    if (ibl) triangle.pass(*ibl, layer_hdr_fbo_, width_, height_, true);

    // 3. Over the HDR target: L = a L_layer + (1 - a) L_behind (alpha of the target kept).
    layer_hdr_.bind(KIT_UNIT_HDR);
    hdr_fbo.bind();
    glViewport(0, 0, width_, height_);
    blend_.use();
    glEnable(GL_BLEND);
    glBlendFuncSeparate(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA, GL_ZERO, GL_ONE);
    triangle.draw();
    glDisable(GL_BLEND);
    glDisable(GL_SCISSOR_TEST);
  }
}

void ForwardPass::draw_light_markers(const std::vector<Light>& lights, const Scene& scene, const GBuffer& opaque,
                                     const Texture2D& hdr) {
  marker_fbo_.attach_color(0, hdr);
  marker_fbo_.attach_depth(opaque.depth());
  marker_fbo_.set_draw_buffers(1);
  marker_fbo_.bind();
  glViewport(0, 0, width_, height_);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  glDepthMask(GL_FALSE);  // the G-buffer's depth stays the opaque surfaces'
  glEnable(GL_CULL_FACE);
  glDisable(GL_BLEND);
  marker_.use();
  marker_.set("u_marker_radius", light_marker_radius(scene));
  for (const Light& light : lights) {
    if (light.type != KIT_LIGHT_POINT && light.type != KIT_LIGHT_SPOT) continue;  // only these have a place
    marker_.set("u_marker_center", light.position);
    marker_.set("u_marker_radiance", light_marker_radiance(light));
    marker_sphere_.draw();
  }
  glDepthMask(GL_TRUE);
}

}  // namespace kit
