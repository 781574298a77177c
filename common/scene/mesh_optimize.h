#pragma once
// Geometry-pass optimisation: mesh statistics and reordering through
// meshoptimizer, plus a conservative view-frustum test for whole draws.
//
// On a software rasteriser (llvmpipe) vertex shading is a large share of a
// frame, so the geometry pass gains from (1) welding duplicated vertices,
// (2) ordering triangles so the post-transform vertex cache hits more often,
// (3) ordering them front-to-back-ish within a mesh to shade fewer hidden
// fragments, and (4) laying vertices out in first-use order for cheaper
// fetches. None of these changes a triangle's vertices or winding, so a
// depth-tested opaque render stays the same apart from order-dependent ties.
//
// Typical use (kit-bench, tools):
//   kit::Scene scene = kit::load_scene(path);
//   kit::MeshStats before = kit::analyze(scene.primitives[0]);
//   kit::optimize_scene(scene);          // before building the Renderer/SceneGpu
//   kit::MeshStats after = kit::analyze(scene.primitives[0]);
//   settings.frustum_culling = true;     // RenderSettings: skip draws outside the view
#include <glm/glm.hpp>

#include <cstddef>

#include "scene/scene.h"

namespace kit {

// Post-transform vertex cache size the statistics model: 16 entries, as
// meshoptimizer's documentation uses for a typical GPU.
inline constexpr unsigned kMeshStatsCacheSize = 16;

struct MeshStats {
  size_t vertex_count = 0;    // vertices in the primitive's vertex buffer
  size_t triangle_count = 0;  // indices / 3
  // Average cache miss ratio: vertex shader runs per triangle (0.5 best, 3 worst).
  float acmr = 0.0f;
  // Average transformed vertex ratio: vertex shader runs per vertex (1 best, 6 worst).
  float atvr = 0.0f;
  // Fragments shaded / pixels covered over meshoptimizer's fixed set of view
  // directions (1 best); an estimate of the mesh's own self-overdraw.
  float overdraw = 0.0f;
  // Bytes fetched / vertex buffer size under a simple fetch-cache model (1 best).
  float overfetch = 0.0f;
};

// Statistics of one primitive as it stands (its current index order).
// An empty primitive gives counts of 0 and ratios of 0.
MeshStats analyze(const Primitive& primitive);

// Welds bit-identical vertices, then reorders triangles for the vertex cache
// and for overdraw, then reorders vertices for fetch locality. Keeps the
// triangle count, every triangle's three vertex values in their order (so
// winding and provoking vertex are unchanged), the material and the bounds
// (still a valid, conservative box: welding only drops duplicates and
// unreferenced vertices).
void optimize_primitive(Primitive& primitive);

// optimize_primitive on every primitive. Call before the scene is uploaded
// (SceneGpu / Renderer copy vertex data at construction).
void optimize_scene(Scene& scene);

// Six planes (a, b, c, d) with unit normals pointing inwards: a point p is
// inside a plane when dot(n, p) + d >= 0. Order: left, right, bottom, top,
// near, far.
struct Frustum {
  glm::vec4 planes[6];
};

// Gribb-Hartmann extraction from a view-projection matrix with OpenGL clip
// conventions (-w <= x, y, z <= w); the planes are in that matrix's input
// space (world space for projection * view), normalised.
Frustum frustum_from(const glm::mat4& view_projection);

// False only when the box [bounds_min, bounds_max] (local space) placed by
// the affine `world` matrix lies entirely outside one frustum plane. The
// world-space box used is the exact enclosing box of the transformed local
// box, so the test is conservative: it may keep an invisible draw near a
// frustum corner but never rejects one that could cover a pixel.
bool intersects(const Frustum& frustum, const glm::vec3& bounds_min, const glm::vec3& bounds_max,
                const glm::mat4& world);

}  // namespace kit
