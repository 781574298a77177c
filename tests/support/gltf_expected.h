#pragma once
// What a loaded scene should hold, worked out in double from its glTF JSON (nlohmann/json),
// and the checks that compare the loader's float results with it.
#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

#include <map>
#include <string>
#include <vector>

#include "base/no_dangling.h"
#include "gl/gl_objects.h"  // Vertex
#include "scene/scene.h"

namespace kit::test {

// Float round-off of composed float matrices versus the same product in double.
constexpr double kMatrixTolerance = 1e-5;
// A unit vector from float arithmetic (normalize, Gram-Schmidt).
constexpr double kUnitTolerance = 1e-5;

// A glTF node's local matrix (its matrix, or T * R * S) in double.
glm::dmat4 local_matrix(const nlohmann::json& node);

// World matrix of every node, by name, walking the default scene from its roots.
std::map<std::string, glm::dmat4> world_matrices(const nlohmann::json& doc);

// The JSON of the generated kit scene `name` ("default", "sphere", ...).
nlohmann::json scene_json(const std::string& name);

// The primitive of the mesh named `mesh_name`; throws std::runtime_error when there is none.
KIT_NO_DANGLING const Primitive& primitive_named(const Scene& scene, const std::string& mesh_name);

// Expects `actual` within kMatrixTolerance of `expected`, element by element.
void expect_matrix_near(const glm::mat4& actual, const glm::dmat4& expected, const std::string& what);

// A vertex with position, normal and UV set 0, the rest zero (before generate_tangents).
Vertex vertex(glm::vec3 p, glm::vec3 n, glm::vec2 uv);

// Expects every vertex's tangent finite, of unit length, orthogonal to its normal
// (unless the normal is zero) and of handedness w = +1 or -1.
void expect_valid_frame(const std::vector<Vertex>& vertices, const std::string& what);

}  // namespace kit::test
