// The meshes kit-scenes writes: a quad and a UV sphere with normals, UVs and tangents.
//
// Tangent convention (what the renderer relies on): TANGENT.w is chosen so that
// cross(N, T.xyz) * w points "up" in the image (towards decreasing glTF v), where the
// normal map's +Y (green) points. A plainly mapped surface has w = +1, a surface whose U
// runs backwards (mirrored) w = -1.
#pragma once

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

#include <cstdint>
#include <vector>

namespace kit_scenes {

struct MeshData {
  std::vector<glm::vec3> positions;
  std::vector<glm::vec3> normals;
  std::vector<glm::vec2> uvs;
  std::vector<glm::vec2> uvs1;      // empty: the mesh is written without TEXCOORD_1
  std::vector<glm::vec4> tangents;  // empty: the mesh is written without TANGENT
  std::vector<std::uint32_t> indices;
};

// Per-vertex tangents from the UV layout (Lengyel's method), so mirrored UVs get w = -1.
void compute_tangents(MeshData& mesh);

// A rectangle centred on the local origin. `right` and `up` are unit vectors in its plane;
// the CCW front face looks along cross(right, up). The image's top edge lies along +up and
// its left edge along -right, or along +right when mirror_u is set.
MeshData make_quad(glm::vec3 right, glm::vec3 up, glm::vec2 size, glm::vec2 uv_repeat,
                   bool mirror_u);

// UV sphere around the origin: u follows the longitude so the image reads left to right
// seen from outside (u = 0.5 at +Z, the seam at -Z), v = 0 at the north pole (+Y). Tangents are
// analytic (the direction of d position / du), which stays exact at the poles and along the seam.
MeshData make_sphere(float radius, int segments, int rings, glm::vec2 uv_repeat,
                     bool with_tangents);

// Rotation that turns a node's local -Z towards `target`, keeping +Y up (cameras, spots).
glm::dquat look_at_rotation(glm::dvec3 eye, glm::dvec3 target);

}  // namespace kit_scenes
