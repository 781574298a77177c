// Tangents (kit::generate_tangents): generated exactly for the primitives a file gives
// without TANGENT, as unit vectors along the UVs' u with the handedness of the mapping,
// finite even for degenerate triangles; a file's own tangents are kept.
#include <gtest/gtest.h>

#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "gltf_expected.h"
#include "kit_test.h"
#include "scene/scene.h"

using nlohmann::json;
using namespace kit::test;  // the helpers of support/ included above

namespace {

TEST(SceneLoaderValid, TangentsGeneratedOnlyWhereMissing) {
  const kit::Scene& scene = kit::test::scene("default");
  json doc = scene_json("default");
  // The loader generates tangents exactly for the primitives written without TANGENT.
  for (const json& mesh : doc["meshes"]) {
    bool has_tangent = mesh["primitives"][0]["attributes"].contains("TANGENT");
    EXPECT_EQ(primitive_named(scene, mesh["name"]).tangents_generated, !has_tangent) << mesh["name"];
  }

  const kit::Primitive& bare = primitive_named(scene, "sphere_no_tangents");
  ASSERT_TRUE(bare.tangents_generated);
  for (size_t i = 0; i < bare.vertices.size(); ++i) {
    const kit::Vertex& v = bare.vertices[i];
    glm::dvec3 t(v.tangent), n = glm::normalize(glm::dvec3(v.normal));
    ASSERT_NEAR(glm::length(t), 1.0, kUnitTolerance) << "vertex " << i;
    ASSERT_NEAR(glm::dot(t, n), 0.0, kUnitTolerance) << "vertex " << i;
    ASSERT_TRUE(v.tangent.w == 1.0f || v.tangent.w == -1.0f) << "vertex " << i << " w " << v.tangent.w;
    // Away from the poles the sphere is plainly mapped (u along longitude, v down the
    // image towards -Y): the tangent follows d(position)/du = (cos phi, 0, -sin phi) and
    // w = +1, as in the generator's analytic tangents for the other spheres.
    if (std::fabs(n.y) < 0.9) {
      glm::dvec3 analytic = glm::normalize(glm::dvec3(n.z, 0.0, -n.x));
      EXPECT_GT(glm::dot(t, analytic), 0.99) << "vertex " << i;
      EXPECT_EQ(v.tangent.w, 1.0f) << "vertex " << i;
    }
  }

  // The mirrored panel brings its own TANGENT with w = -1, which must be kept.
  const kit::Primitive& panel = primitive_named(scene, "mirrored_panel");
  EXPECT_FALSE(panel.tangents_generated);
  ASSERT_FALSE(panel.vertices.empty());
  for (const kit::Vertex& v : panel.vertices) EXPECT_EQ(v.tangent.w, -1.0f);
}

// ---- generate_tangents on hand-made triangles ----

TEST(SceneLoaderTangents, DegenerateUvsGiveFiniteUnitTangents) {
  const std::vector<uint32_t> triangle = {0, 1, 2};
  const glm::vec3 z(0, 0, 1), x(1, 0, 0);
  struct Case {
    std::string name;
    std::vector<kit::Vertex> vertices;
  };
  std::vector<Case> cases = {
      {"all UVs equal", {vertex({0, 0, 0}, z, {0.5f, 0.5f}), vertex({1, 0, 0}, z, {0.5f, 0.5f}), vertex({0, 1, 0}, z, {0.5f, 0.5f})}},
      {"collinear UVs", {vertex({0, 0, 0}, z, {0, 0}), vertex({1, 0, 0}, z, {1, 1}), vertex({0, 1, 0}, z, {2, 2})}},
      {"normal along x", {vertex({0, 0, 0}, x, {0, 0}), vertex({0, 1, 0}, x, {0, 0}), vertex({0, 0, 1}, x, {0, 0})}},
      {"zero-area triangle", {vertex({0, 0, 0}, z, {0, 0}), vertex({0, 0, 0}, z, {1, 0}), vertex({0, 0, 0}, z, {0, 1})}},
      {"zero normal", {vertex({0, 0, 0}, glm::vec3(0), {0, 0}), vertex({1, 0, 0}, glm::vec3(0), {0, 0}),
                       vertex({0, 1, 0}, glm::vec3(0), {0, 0})}},
  };
  for (Case& c : cases) {
    kit::generate_tangents(c.vertices, triangle);
    expect_valid_frame(c.vertices, c.name);
  }
}

TEST(SceneLoaderTangents, PlainAndMirroredQuadsGetTheirHandedness) {
  // A quad facing +Z, u to the right (+X), glTF v down the image (-Y): T = +X, and
  // B = cross(N, T) * w must point up the image (+Y), so w = +1. Mirroring u flips T
  // to -X; then cross(N, T) = -Y and w = -1 keeps B pointing up.
  const glm::vec3 n(0, 0, 1);
  const std::vector<uint32_t> quad = {0, 1, 2, 0, 2, 3};
  for (bool mirrored : {false, true}) {
    auto u = [&](float s) { return mirrored ? 1.0f - s : s; };
    std::vector<kit::Vertex> v = {vertex({0, 0, 0}, n, {u(0), 1}), vertex({1, 0, 0}, n, {u(1), 1}),
                                  vertex({1, 1, 0}, n, {u(1), 0}), vertex({0, 1, 0}, n, {u(0), 0})};
    kit::generate_tangents(v, quad);
    expect_valid_frame(v, mirrored ? "mirrored" : "plain");
    for (const kit::Vertex& vert : v) {
      EXPECT_NEAR(vert.tangent.x, mirrored ? -1.0 : 1.0, kUnitTolerance);
      EXPECT_EQ(vert.tangent.w, mirrored ? -1.0f : 1.0f);
    }
  }
}

}  // namespace
