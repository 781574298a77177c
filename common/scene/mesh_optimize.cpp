#include "scene/mesh_optimize.h"

// KIT_HAS_MESHOPTIMIZER: set by common/CMakeLists.txt; the browser build has no
// meshoptimizer (no WebAssembly build of it in Debian), and there the statistics and
// reordering are refused by name while the frustum test below stays.
#if KIT_HAS_MESHOPTIMIZER
#include <meshoptimizer.h>
#endif

#include <cmath>
#include <vector>

#include "base/error.h"

namespace kit {

namespace {

#if KIT_HAS_MESHOPTIMIZER
// Welding compares whole vertices byte for byte, so Vertex must have no
// padding (uninitialised padding bytes would keep equal vertices apart).
static_assert(sizeof(Vertex) == 14 * sizeof(float) + 4 * sizeof(uint16_t), "Vertex must be tightly packed for byte-wise welding");

// How much the overdraw pass may worsen the vertex cache result (1.05: up to
// 5% more vertex shader runs) in exchange for less overdraw; meshoptimizer's
// recommended value.
constexpr float kOverdrawThreshold = 1.05f;

// Warp and primitive-group sizes of 0 model a plain FIFO cache, as
// meshoptimizer's documentation does for ACMR/ATVR figures.
constexpr unsigned kNoWarpModel = 0;
constexpr unsigned kNoPrimGroupModel = 0;

#endif

// Float rounding in the plane test (plane extraction, matrix products) is a
// few ulps of the magnitudes involved; a box must be outside by more than this
// fraction of them to be culled, so rounding alone never removes a draw.
constexpr float kCullRelativeSlack = 1e-5f;

#if KIT_HAS_MESHOPTIMIZER
const float* positions(const std::vector<Vertex>& vertices) { return &vertices[0].position.x; }
#endif

}  // namespace

#if KIT_HAS_MESHOPTIMIZER
MeshStats analyze(const Primitive& primitive) {
  MeshStats stats;
  stats.vertex_count = primitive.vertices.size();
  stats.triangle_count = primitive.indices.size() / 3;
  if (primitive.indices.empty() || primitive.vertices.empty()) return stats;
  const unsigned* indices = primitive.indices.data();
  const size_t index_count = primitive.indices.size();
  const size_t vertex_count = primitive.vertices.size();
  meshopt_VertexCacheStatistics cache =
      meshopt_analyzeVertexCache(indices, index_count, vertex_count, kMeshStatsCacheSize, kNoWarpModel, kNoPrimGroupModel);
  stats.acmr = cache.acmr;
  stats.atvr = cache.atvr;
  stats.overdraw =
      meshopt_analyzeOverdraw(indices, index_count, positions(primitive.vertices), vertex_count, sizeof(Vertex)).overdraw;
  stats.overfetch = meshopt_analyzeVertexFetch(indices, index_count, vertex_count, sizeof(Vertex)).overfetch;
  return stats;
}

void optimize_primitive(Primitive& primitive) {
  // Nothing is drawn without indices; an empty primitive stays as it is.
  if (primitive.indices.empty() || primitive.vertices.empty()) return;
  std::vector<unsigned>& indices = primitive.indices;
  const size_t index_count = indices.size();

  // 1. Weld: one vertex per distinct Vertex value among those the indices use.
  std::vector<unsigned> remap(primitive.vertices.size());
  const size_t unique = meshopt_generateVertexRemap(remap.data(), indices.data(), index_count, primitive.vertices.data(),
                                                    primitive.vertices.size(), sizeof(Vertex));
  std::vector<Vertex> welded(unique);
  meshopt_remapVertexBuffer(welded.data(), primitive.vertices.data(), primitive.vertices.size(), sizeof(Vertex),
                            remap.data());
  meshopt_remapIndexBuffer(indices.data(), indices.data(), index_count, remap.data());

  // 2. Triangle order for the post-transform vertex cache.
  std::vector<unsigned> cache_ordered(index_count);
  meshopt_optimizeVertexCache(cache_ordered.data(), indices.data(), index_count, unique);

  // 3. Triangle clusters ordered to shade fewer hidden fragments; it needs the
  //    cache-optimised order as input (it keeps the clusters that order forms).
  meshopt_optimizeOverdraw(indices.data(), cache_ordered.data(), index_count, positions(welded), unique, sizeof(Vertex),
                           kOverdrawThreshold);

  // 4. Vertices in first-use order; rewrites the indices in place.
  std::vector<Vertex> fetch_ordered(unique);
  const size_t used =
      meshopt_optimizeVertexFetch(fetch_ordered.data(), indices.data(), index_count, welded.data(), unique, sizeof(Vertex));
  fetch_ordered.resize(used);
  primitive.vertices = std::move(fetch_ordered);
}

#else
MeshStats analyze(const Primitive&) {
  throw Error("mesh statistics need meshoptimizer, which this build of the kit (the browser's) leaves out");
}

void optimize_primitive(Primitive&) {
  throw Error("mesh optimisation needs meshoptimizer, which this build of the kit (the browser's) leaves out");
}
#endif

void optimize_scene(Scene& scene) {
  for (Primitive& p : scene.primitives) optimize_primitive(p);
}

Frustum frustum_from(const glm::mat4& view_projection) {
  // GLM is column-major: m[column][row]. Row i of the matrix dotted with a
  // point gives its clip coordinate i; -w <= x gives row3 + row0 >= 0, etc.
  const glm::mat4& m = view_projection;
  auto row = [&](int r) { return glm::vec4(m[0][r], m[1][r], m[2][r], m[3][r]); };
  const glm::vec4 x = row(0), y = row(1), z = row(2), w = row(3);
  Frustum f{{w + x, w - x, w + y, w - y, w + z, w - z}};
  for (glm::vec4& plane : f.planes) {
    const float length = glm::length(glm::vec3(plane));
    // A zero normal (the far plane of an infinite projection) is left as it
    // is: its d >= 0 keeps every point inside.
    if (length > 0.0f) plane /= length;
  }
  return f;
}

bool intersects(const Frustum& frustum, const glm::vec3& bounds_min, const glm::vec3& bounds_max, const glm::mat4& world) {
  // World box enclosing the transformed local box (Arvo): the centre maps
  // through the matrix, each world half-extent is the sum of |M| times the
  // local half-extents.
  const glm::vec3 local_center = 0.5f * (bounds_min + bounds_max);
  const glm::vec3 local_half = 0.5f * (bounds_max - bounds_min);
  const glm::vec3 center = glm::vec3(world * glm::vec4(local_center, 1.0f));
  const glm::mat3 linear(world);
  const glm::mat3 abs_linear(glm::abs(linear[0]), glm::abs(linear[1]), glm::abs(linear[2]));
  const glm::vec3 half = abs_linear * glm::abs(local_half);
  for (const glm::vec4& plane : frustum.planes) {
    const glm::vec3 normal(plane);
    const float center_term = glm::dot(normal, center);
    const float distance = center_term + plane.w;          // signed distance of the centre
    const float radius = glm::dot(glm::abs(normal), half);  // box's reach along the normal
    const float slack = kCullRelativeSlack * (std::fabs(center_term) + std::fabs(plane.w) + radius);
    if (distance + radius < -slack) return false;  // every corner is outside this plane
  }
  return true;
}

}  // namespace kit
