#include "scene_meshes.h"

#include <cmath>

#include "scene_math.h"

namespace kit_scenes {

// Per-vertex tangents from the UV layout (Lengyel's method), so mirrored UVs get w = -1.
void compute_tangents(MeshData& mesh) {
  std::vector<glm::vec3> dp_du(mesh.positions.size(), glm::vec3(0.0f));
  std::vector<glm::vec3> dp_dup(mesh.positions.size(), glm::vec3(0.0f));
  for (size_t i = 0; i + 2 < mesh.indices.size(); i += 3) {
    const std::uint32_t i0 = mesh.indices[i], i1 = mesh.indices[i + 1], i2 = mesh.indices[i + 2];
    const glm::vec3 e1 = mesh.positions[i1] - mesh.positions[i0];
    const glm::vec3 e2 = mesh.positions[i2] - mesh.positions[i0];
    // Second component is "up" in the image (decreasing glTF v), where the map's +Y points.
    const glm::vec2 d1(mesh.uvs[i1].x - mesh.uvs[i0].x, mesh.uvs[i0].y - mesh.uvs[i1].y);
    const glm::vec2 d2(mesh.uvs[i2].x - mesh.uvs[i0].x, mesh.uvs[i0].y - mesh.uvs[i2].y);
    const float det = d1.x * d2.y - d2.x * d1.y;
    if (std::abs(det) < 1e-12f) continue;  // degenerate UVs say nothing about the tangent
    const glm::vec3 s = (e1 * d2.y - e2 * d1.y) / det;
    const glm::vec3 t = (e2 * d1.x - e1 * d2.x) / det;
    for (std::uint32_t v : {i0, i1, i2}) {
      dp_du[v] += s;
      dp_dup[v] += t;
    }
  }
  mesh.tangents.resize(mesh.positions.size());
  for (size_t v = 0; v < mesh.positions.size(); ++v) {
    const glm::vec3 n = mesh.normals[v];
    const glm::vec3 t = glm::normalize(dp_du[v] - n * glm::dot(n, dp_du[v]));  // Gram-Schmidt
    const float w = glm::dot(glm::cross(n, t), dp_dup[v]) < 0.0f ? -1.0f : 1.0f;
    mesh.tangents[v] = glm::vec4(t, w);
  }
}

// A rectangle centred on the local origin. `right` and `up` are unit vectors in its plane;
// the CCW front face looks along cross(right, up). The image's top edge lies along +up and
// its left edge along -right, or along +right when mirror_u is set.
MeshData make_quad(glm::vec3 right, glm::vec3 up, glm::vec2 size, glm::vec2 uv_repeat,
                   bool mirror_u) {
  MeshData mesh;
  const glm::vec3 normal = glm::normalize(glm::cross(right, up));
  const glm::vec2 corners[4] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};  // BL, BR, TR, TL
  for (const glm::vec2& c : corners) {
    mesh.positions.push_back(right * ((c.x - 0.5f) * size.x) + up * ((c.y - 0.5f) * size.y));
    mesh.normals.push_back(normal);
    const float u = mirror_u ? 1.0f - c.x : c.x;
    mesh.uvs.emplace_back(u * uv_repeat.x, (1.0f - c.y) * uv_repeat.y);
  }
  mesh.indices = {0, 1, 2, 0, 2, 3};
  compute_tangents(mesh);
  return mesh;
}

// UV sphere around the origin: u follows the longitude so the image reads left to right
// seen from outside (u = 0.5 at +Z, the seam at -Z), v = 0 at the north pole (+Y). Tangents are
// analytic (the direction of d position / du), which stays exact at the poles and along the seam.
MeshData make_sphere(float radius, int segments, int rings, glm::vec2 uv_repeat,
                     bool with_tangents) {
  MeshData mesh;
  const int columns = segments + 1;  // the seam column is duplicated for the UV wrap
  for (int r = 0; r <= rings; ++r) {
    const float v = float(r) / float(rings);
    const double theta = kPi * v;
    for (int s = 0; s <= segments; ++s) {
      // Pole vertices take their triangle's centre u, which limits the pinch distortion.
      const bool pole = (r == 0 || r == rings);
      const float u = (float(s) + (pole ? 0.5f : 0.0f)) / float(segments);
      const double phi = 2.0 * kPi * (u - 0.5);
      const glm::vec3 n(float(std::sin(theta) * std::sin(phi)), float(std::cos(theta)),
                        float(std::sin(theta) * std::cos(phi)));
      mesh.positions.push_back(radius * n);
      mesh.normals.push_back(n);
      mesh.uvs.emplace_back(u * uv_repeat.x, v * uv_repeat.y);
      if (with_tangents)
        mesh.tangents.emplace_back(float(std::cos(phi)), 0.0f, float(-std::sin(phi)), 1.0f);
    }
  }
  // a-b on the upper ring, c-d below. The pole rows collapse to one triangle per segment,
  // which leaves the last vertex of each pole row unreferenced (kept for a regular grid).
  for (int r = 0; r < rings; ++r) {
    for (int s = 0; s < segments; ++s) {
      const std::uint32_t a = std::uint32_t(r * columns + s), b = a + 1;
      const std::uint32_t c = a + std::uint32_t(columns), d = c + 1;
      if (r == 0)
        mesh.indices.insert(mesh.indices.end(), {a, c, d});
      else if (r == rings - 1)
        mesh.indices.insert(mesh.indices.end(), {a, c, b});
      else
        mesh.indices.insert(mesh.indices.end(), {a, c, d, a, d, b});
    }
  }
  return mesh;
}

// Rotation that turns a node's local -Z towards `target`, keeping +Y up (cameras, spots).
glm::dquat look_at_rotation(glm::dvec3 eye, glm::dvec3 target) {
  return glm::quatLookAtRH(glm::normalize(target - eye), glm::dvec3(0.0, 1.0, 0.0));
}

}  // namespace kit_scenes
