// The glTF loader's accessors (common/scene/gltf_accessors.cpp): interleaved views,
// sparse accessors, normalized and quantized integer components and vertex colours
// decode as glTF 2.0 says, computed here in double; other formats are refused by name.
#include <gtest/gtest.h>

#include <glm/glm.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <utility>
#include <vector>

#include "kit_test.h"
#include "render/stages.h"
#include "scene/scene.h"
#include "scene_copy.h"

using nlohmann::json;
using namespace kit::test;  // the helpers of support/ included above

namespace {

const char* vec_type(size_t components) { return components == 2 ? "VEC2" : components == 3 ? "VEC3" : "VEC4"; }

// An accessor of `count` elements of `components` integers of type T (glTF
// component type `component_type`) in a new bufferView, component k of all of
// them being values[k % size]; elements padded to 4 bytes as vertex data must be.
template <typename T>
int add_integer_accessor(SceneCopy& copy, const std::vector<T>& values, size_t count, size_t components,
                         int component_type, bool normalized) {
  const size_t element = components * sizeof(T), stride = (element + 3) / 4 * 4;
  std::string bytes(count * stride, '\0');
  for (size_t v = 0; v < count; ++v)
    for (size_t c = 0; c < components; ++c)
      std::memcpy(&bytes[v * stride + c * sizeof(T)], &values[(v * components + c) % values.size()], sizeof(T));
  const int view = copy.add_view(bytes, stride != element ? stride : 0);
  return copy.add_accessor({{"bufferView", view}, {"componentType", component_type}, {"normalized", normalized},
                            {"count", count}, {"type", vec_type(components)}});
}

// The copy's first primitive's vertices once the file requires KHR_mesh_quantization.
std::vector<kit::Vertex> first_primitive_with_quantization(SceneCopy& copy) {
  copy.require_extension("KHR_mesh_quantization");
  copy.save_json();
  return kit::load_scene(copy.gltf.string()).primitives.at(0).vertices;
}

// glTF 2.0's decoding of a normalized integer component c, in double.
double normalized_value(double c, int component_type) {
  switch (component_type) {
    case 5120: return std::max(c / 127.0, -1.0);    // BYTE
    case 5121: return c / 255.0;                    // UNSIGNED_BYTE
    case 5122: return std::max(c / 32767.0, -1.0);  // SHORT
    default: return c / 65535.0;                    // UNSIGNED_SHORT
  }
}
// A float from float arithmetic on a value in [-1, 1] (one rounding step).
constexpr double kNormalizedTolerance = 1e-7;

void expect_same_vertices(const kit::Primitive& expected, const kit::Primitive& actual) {
  ASSERT_EQ(actual.vertices.size(), expected.vertices.size());
  EXPECT_EQ(actual.indices, expected.indices);
  for (size_t i = 0; i < actual.vertices.size(); ++i) {
    const kit::Vertex &a = actual.vertices[i], &e = expected.vertices[i];
    ASSERT_TRUE(a.position == e.position && a.normal == e.normal && a.texcoord == e.texcoord && a.tangent == e.tangent)
        << "vertex " << i;
  }
}

TEST(SceneLoaderAccessors, InterleavedViewGivesTheSameVerticesAsSeparateViews) {
  SceneCopy copy("sphere", "interleaved");
  const std::pair<std::string, size_t> attributes[] = {{"POSITION", 3}, {"NORMAL", 3}, {"TEXCOORD_0", 2}, {"TANGENT", 4}};
  const size_t count = copy.doc["accessors"][static_cast<size_t>(copy.accessor("POSITION"))]["count"];
  const size_t stride = 4 * (3 + 3 + 2 + 4);
  std::string interleaved(count * stride, '\0');
  size_t offset = 0;
  for (const auto& [name, components] : attributes) {
    const std::vector<float> values = copy.floats(copy.accessor(name), components);
    for (size_t v = 0; v < count; ++v) std::memcpy(&interleaved[v * stride + offset], &values[v * components], 4 * components);
    offset += 4 * components;
  }
  const int view = copy.add_view(interleaved, stride);
  offset = 0;
  for (const auto& [name, components] : attributes) {
    json& accessor = copy.doc["accessors"][static_cast<size_t>(copy.accessor(name))];
    accessor["bufferView"] = view;
    accessor["byteOffset"] = offset;
    offset += 4 * components;
  }
  copy.save_json();
  const kit::Scene separate = kit::load_scene(kit::resolve_scene("sphere"));
  const kit::Scene scene = kit::load_scene(copy.gltf.string());
  expect_same_vertices(separate.primitives.at(0), scene.primitives.at(0));
}

TEST(SceneLoaderAccessors, SparseValuesReplaceTheListedVertices) {
  SceneCopy copy("sphere", "sparse");
  const std::vector<uint16_t> moved = {3, 17, 1000};
  const std::vector<float> values = {0.5f, 2.0f, -1.0f, 3.0f, 0.0f, 0.25f, -2.0f, -2.0f, 1.5f};
  copy.doc["accessors"][static_cast<size_t>(copy.accessor("POSITION"))]["sparse"] = {
      {"count", moved.size()},
      {"indices", {{"bufferView", copy.add_view(bytes_of(moved))}, {"componentType", 5123}}},
      {"values", {{"bufferView", copy.add_view(bytes_of(values))}}}};
  copy.save_json();
  const kit::Primitive& dense = kit::test::scene("sphere").primitives.at(0);
  const kit::Scene scene = kit::load_scene(copy.gltf.string());
  const kit::Primitive& sparse = scene.primitives.at(0);
  ASSERT_EQ(sparse.vertices.size(), dense.vertices.size());
  for (size_t v = 0; v < sparse.vertices.size(); ++v) {
    auto k = std::find(moved.begin(), moved.end(), v);
    glm::vec3 expected = dense.vertices[v].position;
    if (k != moved.end()) expected = glm::make_vec3(&values[3 * static_cast<size_t>(k - moved.begin())]);
    ASSERT_EQ(sparse.vertices[v].position, expected) << "vertex " << v;
  }
  EXPECT_EQ(sparse.bounds_min.x, -2.0f) << "bounds follow the sparse values";
}

// Without a bufferView a sparse accessor starts from zeros.
TEST(SceneLoaderAccessors, SparseAccessorWithoutBufferViewStartsFromZeros) {
  SceneCopy copy("sphere", "sparse_zeros");
  const size_t count = copy.doc["accessors"][static_cast<size_t>(copy.accessor("TEXCOORD_0"))]["count"];
  const std::vector<uint8_t> moved = {5, 9};
  const std::vector<float> values = {0.25f, 0.75f, 1.0f, 0.5f};
  const int uv = copy.add_accessor(
      {{"componentType", 5126}, {"count", count}, {"type", "VEC2"},
       {"sparse", {{"count", moved.size()},
                   {"indices", {{"bufferView", copy.add_view(bytes_of(moved))}, {"componentType", 5121}}},
                   {"values", {{"bufferView", copy.add_view(bytes_of(values))}}}}}});
  copy.doc["meshes"][0]["primitives"][0]["attributes"]["TEXCOORD_0"] = uv;
  copy.save_json();
  const kit::Scene scene = kit::load_scene(copy.gltf.string());
  const std::vector<kit::Vertex>& vertices = scene.primitives.at(0).vertices;
  ASSERT_EQ(vertices.size(), count);
  for (size_t v = 0; v < count; ++v) {
    glm::vec2 expected(0.0f);
    if (v == 5) expected = {0.25f, 0.75f};
    if (v == 9) expected = {1.0f, 0.5f};
    ASSERT_EQ(vertices[v].texcoord, expected) << "vertex " << v;
  }
}

TEST(SceneLoaderAccessors, SparseIndexPastTheCountIsRefused) {
  SceneCopy copy("sphere", "sparse_out_of_range");
  const int position = copy.accessor("POSITION");
  const uint32_t count = copy.doc["accessors"][static_cast<size_t>(position)]["count"];
  const std::vector<uint32_t> moved = {3, count};
  copy.doc["accessors"][static_cast<size_t>(position)]["sparse"] = {
      {"count", moved.size()},
      {"indices", {{"bufferView", copy.add_view(bytes_of(moved))}, {"componentType", 5125}}},
      {"values", {{"bufferView", copy.add_view(std::string(moved.size() * 12, '\0'))}}}};
  copy.save_json();
  expect_scene_error(copy.gltf, "POSITION: accessor " + std::to_string(position) + ": sparse index " + std::to_string(count) +
                              " at position 1 is out of range");
  // A sparse count beyond the accessor's, whose indices would run past their view.
  copy.doc["accessors"][static_cast<size_t>(position)]["sparse"]["count"] = count + 1;
  copy.save_json();
  expect_scene_error(copy.gltf, "sparse count " + std::to_string(count + 1) + " is not between 1 and");
}

// Normalized integers decode as glTF 2.0 says (c / 255, max(c / 127, -1), ...),
// each at its extremes; NORMAL may be normalized BYTE/SHORT only with KHR_mesh_quantization.
TEST(SceneLoaderAccessors, NormalizedIntegersDecodeAsTheSpecSays) {
  const std::vector<int8_t> bytes = {-128, -127, -64, 0, 1, 64, 127};
  const std::vector<int16_t> shorts = {-32768, -32767, -1, 0, 1, 16384, 32767};
  const std::vector<uint8_t> unsigned_bytes = {0, 1, 128, 254, 255};
  const std::vector<uint16_t> unsigned_shorts = {0, 1, 32768, 65534, 65535};
  for (bool eight_bit : {true, false}) {
    SceneCopy copy("sphere", eight_bit ? "normalized8" : "normalized16");
    const size_t count = copy.doc["accessors"][0]["count"];
    json& attributes = copy.doc["meshes"][0]["primitives"][0]["attributes"];
    const int normal_type = eight_bit ? 5120 : 5122, uv_type = eight_bit ? 5123 : 5121;  // 16-bit UVs with 8-bit normals
    attributes["NORMAL"] = eight_bit ? add_integer_accessor(copy, bytes, count, 3, normal_type, true)
                                     : add_integer_accessor(copy, shorts, count, 3, normal_type, true);
    attributes["TEXCOORD_0"] = eight_bit ? add_integer_accessor(copy, unsigned_shorts, count, 2, uv_type, true)
                                         : add_integer_accessor(copy, unsigned_bytes, count, 2, uv_type, true);
    copy.save_json();
    expect_scene_error(copy.gltf, "NORMAL: accessor " + std::to_string(attributes["NORMAL"].get<int>()) +
                                " has an unsupported component type normalized " + (eight_bit ? "BYTE" : "SHORT") +
                                " (allowed only in a file that uses KHR_mesh_quantization)");
    const std::vector<kit::Vertex> vertices = first_primitive_with_quantization(copy);
    ASSERT_EQ(vertices.size(), count);
    for (size_t v = 0; v < count; ++v) {
      for (size_t c = 0; c < 3; ++c) {
        const size_t k = v * 3 + c;
        const double raw = eight_bit ? bytes[k % bytes.size()] : shorts[k % shorts.size()];
        ASSERT_NEAR(vertices[v].normal[static_cast<int>(c)], normalized_value(raw, normal_type), kNormalizedTolerance)
            << "vertex " << v << " normal " << c << " from " << raw;
      }
      for (size_t c = 0; c < 2; ++c) {
        const size_t k = v * 2 + c;
        const double raw = eight_bit ? unsigned_shorts[k % unsigned_shorts.size()] : unsigned_bytes[k % unsigned_bytes.size()];
        ASSERT_NEAR(vertices[v].texcoord[static_cast<int>(c)], normalized_value(raw, uv_type), kNormalizedTolerance)
            << "vertex " << v << " uv " << c << " from " << raw;
      }
    }
  }
}

// KHR_mesh_quantization: plain (not normalized) integer positions and UVs are their values.
TEST(SceneLoaderAccessors, QuantizedPositionsNeedKhrMeshQuantization) {
  SceneCopy copy("sphere", "quantized");
  const size_t count = copy.doc["accessors"][0]["count"];
  const std::vector<int16_t> positions = {-32768, -300, 0, 7, 32767};
  const std::vector<uint8_t> uvs = {0, 3, 255};
  json& attributes = copy.doc["meshes"][0]["primitives"][0]["attributes"];
  attributes["POSITION"] = add_integer_accessor(copy, positions, count, 3, 5122, false);  // 6 bytes in 8
  attributes["TEXCOORD_0"] = add_integer_accessor(copy, uvs, count, 2, 5121, false);     // 2 bytes in 4
  copy.save_json();
  expect_scene_error(copy.gltf, "POSITION: accessor " + std::to_string(attributes["POSITION"].get<int>()) +
                              " has an unsupported component type SHORT (allowed only in a file that uses KHR_mesh_quantization)");
  const std::vector<kit::Vertex> vertices = first_primitive_with_quantization(copy);
  ASSERT_EQ(vertices.size(), count);
  for (size_t v = 0; v < count; ++v) {
    for (int c = 0; c < 3; ++c)
      ASSERT_EQ(vertices[v].position[c], positions[(v * 3 + static_cast<size_t>(c)) % positions.size()]) << "vertex " << v;
    for (int c = 0; c < 2; ++c)
      ASSERT_EQ(vertices[v].texcoord[c], uvs[(v * 2 + static_cast<size_t>(c)) % uvs.size()]) << "vertex " << v;
  }
}

// COLOR_0 as glTF 2.0 decodes it (FLOAT as it is, c / 255, c / 65535; VEC3 means
// alpha 1), through the kit's 16-bit store. Vertex::color keeps 8- and 16-bit colours
// exactly (c8 / 255 = c8 * 257 / 65535) and a float within half a 16-bit step.
double stored_color(const kit::Vertex& v, int c) { return v.color[c] / 65535.0; }
constexpr double kLosslessColorTolerance = 1e-12;       // double round-off of c / 255 against c * 257 / 65535
constexpr double kFloatColorTolerance = 0.5 / 65535.0;  // rounding a float to 16 bits

TEST(SceneLoaderAccessors, VertexColoursDecodeAsTheSpecSays) {
  const std::vector<float> floats = {0.0f, 0.125f, 0.3f, 0.5f, 0.999f, 1.0f, 0.0001f};
  const std::vector<uint8_t> unsigned_bytes = {0, 1, 64, 128, 254, 255, 37};
  const std::vector<uint16_t> unsigned_shorts = {0, 1, 257, 32768, 65534, 65535, 12345};
  struct Case {
    const char* name;
    int component_type;  // 5126 FLOAT, 5121 UNSIGNED_BYTE, 5123 UNSIGNED_SHORT
    size_t components;
  };
  // UNSIGNED_SHORT VEC3 is 6 bytes padded to 8: a byteStride the reader must follow.
  for (const Case& k : {Case{"float_vec3", 5126, 3}, Case{"ubyte_vec4", 5121, 4}, Case{"ushort_vec3", 5123, 3},
                        Case{"ushort_vec4", 5123, 4}}) {
    SCOPED_TRACE(k.name);
    SceneCopy copy("sphere", std::string("color_") + k.name);
    const size_t count = copy.doc["accessors"][0]["count"];
    json& attributes = copy.doc["meshes"][0]["primitives"][0]["attributes"];
    attributes["COLOR_0"] = k.component_type == 5126   ? add_integer_accessor(copy, floats, count, k.components, 5126, false)
                            : k.component_type == 5121 ? add_integer_accessor(copy, unsigned_bytes, count, k.components, 5121, true)
                                                       : add_integer_accessor(copy, unsigned_shorts, count, k.components, 5123, true);
    copy.save_json();
    const kit::Scene scene = kit::load_scene(copy.gltf.string());
    EXPECT_TRUE(scene.warnings.empty()) << scene.warnings.front();
    const std::vector<kit::Vertex>& vertices = scene.primitives.at(0).vertices;
    ASSERT_EQ(vertices.size(), count);
    size_t changed = 0;
    for (size_t v = 0; v < count; ++v)
      for (size_t c = 0; c < 4; ++c) {
        const size_t i = v * k.components + c;
        double expected = 1.0;  // VEC3: alpha 1
        if (c < k.components)
          expected = k.component_type == 5126   ? double{floats[i % floats.size()]}
                     : k.component_type == 5121 ? normalized_value(unsigned_bytes[i % unsigned_bytes.size()], 5121)
                                                : normalized_value(unsigned_shorts[i % unsigned_shorts.size()], 5123);
        ASSERT_NEAR(stored_color(vertices[v], static_cast<int>(c)), expected,
                    k.component_type == 5126 ? kFloatColorTolerance : kLosslessColorTolerance)
            << "vertex " << v << " component " << c;
        changed += expected < 0.5;
      }
    EXPECT_GT(changed, count) << "the premise: the colours are far from the white of a mesh without COLOR_0";
  }
  // Without COLOR_0 every vertex is white.
  for (const kit::Vertex& v : kit::test::scene("sphere").primitives.at(0).vertices)
    ASSERT_EQ(v.color, glm::u16vec4(65535));
}

// A sparse COLOR_0 without bufferView: zeros (black, alpha 0) but where listed.
TEST(SceneLoaderAccessors, SparseVertexColoursStartFromZeros) {
  SceneCopy copy("sphere", "color_sparse");
  const size_t count = copy.doc["accessors"][0]["count"];
  const std::vector<uint8_t> moved = {2, 7};
  const std::vector<uint8_t> values = {255, 128, 0, 255, 10, 20, 30, 40};
  const int color = copy.add_accessor(
      {{"componentType", 5121}, {"normalized", true}, {"count", count}, {"type", "VEC4"},
       {"sparse", {{"count", moved.size()},
                   {"indices", {{"bufferView", copy.add_view(bytes_of(moved))}, {"componentType", 5121}}},
                   {"values", {{"bufferView", copy.add_view(bytes_of(values))}}}}}});
  copy.doc["meshes"][0]["primitives"][0]["attributes"]["COLOR_0"] = color;
  copy.save_json();
  const std::vector<kit::Vertex> vertices = kit::load_scene(copy.gltf.string()).primitives.at(0).vertices;
  for (size_t v = 0; v < vertices.size(); ++v)
    for (int c = 0; c < 4; ++c) {
      const size_t k = static_cast<size_t>(std::find(moved.begin(), moved.end(), v) - moved.begin());
      const double expected = k < moved.size() ? normalized_value(values[4 * k + static_cast<size_t>(c)], 5121) : 0.0;
      ASSERT_NEAR(stored_color(vertices[v], c), expected, kLosslessColorTolerance) << "vertex " << v;
    }
}

// COLOR_0 of another type or component type is refused naming the file, the mesh,
// the primitive and the reason; FLOAT values outside [0, 1] are clamped with a warning.
TEST(SceneLoaderErrors, VertexColoursOfAnotherFormatAreRefused) {
  SceneCopy copy("sphere", "color_refused");
  const size_t count = copy.doc["accessors"][0]["count"];
  json& attributes = copy.doc["meshes"][0]["primitives"][0]["attributes"];
  const std::string where = "mesh 0 ('" + copy.doc["meshes"][0].value("name", std::string()) + "') primitive 0 COLOR_0: accessor ";
  const std::vector<uint8_t> bytes = {10, 200};
  attributes["COLOR_0"] = add_integer_accessor(copy, bytes, count, 2, 5121, true);
  copy.save_json();
  expect_scene_error(copy.gltf, where + std::to_string(attributes["COLOR_0"].get<int>()) + " is VEC2; COLOR_0 must be VEC3 or VEC4");
  attributes["COLOR_0"] = add_integer_accessor(copy, bytes, count, 4, 5121, false);
  copy.save_json();
  expect_scene_error(copy.gltf, where + std::to_string(attributes["COLOR_0"].get<int>()) +
                              " has an unsupported component type UNSIGNED_BYTE");
  const std::vector<int8_t> signed_bytes = {-5, 100};
  attributes["COLOR_0"] = add_integer_accessor(copy, signed_bytes, count, 4, 5120, true);
  copy.save_json();
  expect_scene_error(copy.gltf, where + std::to_string(attributes["COLOR_0"].get<int>()) +
                              " has an unsupported component type normalized BYTE");
  // KHR_mesh_quantization widens POSITION, NORMAL, TANGENT and TEXCOORD, not COLOR_0.
  copy.require_extension("KHR_mesh_quantization");
  copy.save_json();
  expect_scene_error(copy.gltf, "unsupported component type normalized BYTE");

  SceneCopy bright("sphere", "color_clamped");
  const std::vector<float> floats = {1.5f, -0.25f, 0.5f};
  bright.doc["meshes"][0]["primitives"][0]["attributes"]["COLOR_0"] = add_integer_accessor(bright, floats, count, 3, 5126, false);
  bright.save_json();
  const kit::Scene scene = kit::load_scene(bright.gltf.string());
  ASSERT_EQ(scene.warnings.size(), 1u);
  EXPECT_NE(scene.warnings[0].find("COLOR_0 has FLOAT values outside [0, 1]; clamped"), std::string::npos) << scene.warnings[0];
  const kit::Vertex& first = scene.primitives.at(0).vertices.at(0);
  EXPECT_EQ(first.color, glm::u16vec4(65535, 0, 32768, 65535));
}

}  // namespace
