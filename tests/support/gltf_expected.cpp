#include "gltf_expected.h"

#include <gtest/gtest.h>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>

#include <cmath>
#include <cstddef>
#include <functional>
#include <stdexcept>

#include "kit_test_files.h"
#include "render/stages.h"  // resolve_scene

namespace kit::test {

using nlohmann::json;

glm::dmat4 local_matrix(const json& node) {
  if (node.contains("matrix")) {
    glm::dmat4 m;
    for (int i = 0; i < 16; ++i) m[i / 4][i % 4] = node["matrix"][static_cast<size_t>(i)].get<double>();
    return m;
  }
  glm::dmat4 m(1.0);
  if (node.contains("translation"))
    m = glm::translate(m, glm::dvec3(node["translation"][0], node["translation"][1], node["translation"][2]));
  if (node.contains("rotation")) {
    const json& r = node["rotation"];  // glTF order x, y, z, w
    m *= glm::mat4_cast(glm::dquat(r[3].get<double>(), r[0].get<double>(), r[1].get<double>(), r[2].get<double>()));
  }
  if (node.contains("scale")) m = glm::scale(m, glm::dvec3(node["scale"][0], node["scale"][1], node["scale"][2]));
  return m;
}

std::map<std::string, glm::dmat4> world_matrices(const json& doc) {
  std::map<std::string, glm::dmat4> out;
  std::function<void(size_t, const glm::dmat4&)> visit = [&](size_t index, const glm::dmat4& parent) {
    const json& node = doc["nodes"][index];
    glm::dmat4 world = parent * local_matrix(node);
    out[node.value("name", "")] = world;
    for (const json& child : node.value("children", json::array())) visit(child.get<size_t>(), world);
  };
  for (const json& root : doc["scenes"][doc.value("scene", 0)]["nodes"]) visit(root.get<size_t>(), glm::dmat4(1.0));
  return out;
}

json scene_json(const std::string& name) { return json::parse(read_file(resolve_scene(name))); }

const Primitive& primitive_named(const Scene& scene, const std::string& mesh_name) {
  for (const Primitive& p : scene.primitives)
    if (p.name.find("('" + mesh_name + "')") != std::string::npos) return p;
  throw std::runtime_error("no primitive of mesh '" + mesh_name + "' in " + scene.path);
}

void expect_matrix_near(const glm::mat4& actual, const glm::dmat4& expected, const std::string& what) {
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r)
      EXPECT_NEAR(actual[c][r], expected[c][r], kMatrixTolerance) << what << " [" << c << "][" << r << "]";
}

Vertex vertex(glm::vec3 p, glm::vec3 n, glm::vec2 uv) { return {p, n, uv, glm::vec2(0.0f), glm::vec4(0.0f)}; }

void expect_valid_frame(const std::vector<Vertex>& vertices, const std::string& what) {
  for (size_t i = 0; i < vertices.size(); ++i) {
    const glm::vec4& t = vertices[i].tangent;
    ASSERT_TRUE(std::isfinite(t.x) && std::isfinite(t.y) && std::isfinite(t.z) && std::isfinite(t.w)) << what << " " << i;
    EXPECT_NEAR(glm::length(glm::dvec3(t)), 1.0, kUnitTolerance) << what << " " << i;
    glm::dvec3 n(vertices[i].normal);
    if (glm::length(n) > 0.0) {
      EXPECT_NEAR(glm::dot(glm::dvec3(t), glm::normalize(n)), 0.0, kUnitTolerance) << what << " " << i;
    }
    EXPECT_TRUE(t.w == 1.0f || t.w == -1.0f) << what << " " << i;
  }
}

}  // namespace kit::test
