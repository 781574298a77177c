// The glTF loader (common/scene/scene.*): broken files fail with a kit::Error naming
// the file and the problem, never a crash; valid kit scenes load with the
// counts, lights, camera, transforms and tangents the glTF JSON describes.
// Expected values come from the JSON itself (nlohmann/json) in double precision.
#include <gtest/gtest.h>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <nlohmann/json.hpp>

#include <sys/stat.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <functional>
#include <limits>
#include <map>
#include <stdexcept>
#include <string>

#include "base/error.h"
#include "gbuffer_layout.h"
#include "kit_test.h"
#include "kit_test_files.h"
#include "scene/scene.h"
#include "render/stages.h"
#include "images/texture_decode.h"
#include "tiny_scenes.h"

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

// Float round-off of composed float matrices versus the same product in double.
constexpr double kMatrixTolerance = 1e-5;
// A unit vector from float arithmetic (normalize, Gram-Schmidt).
constexpr double kUnitTolerance = 1e-5;

// A generated kit scene copied into a fresh temp folder, to be broken by a test.
struct SceneCopy {
  fs::path dir, gltf, bin;
  json doc;

  SceneCopy(const std::string& scene, const std::string& case_name) {
    dir = kit::test::temp_dir("scene_loader/" + case_name);
    gltf = kit::test::copy_scene(scene, dir);
    bin = dir / (gltf.stem().string() + ".bin");
    doc = json::parse(kit::test::read_file(gltf));
  }
  void save_json() const { kit::test::write_file(gltf, doc.dump(2)); }

  // Accessor index of the first primitive's attribute ("POSITION", ...) or "indices".
  int accessor(const std::string& attribute) const {
    const json& prim = doc["meshes"][0]["primitives"][0];
    return attribute == "indices" ? prim["indices"].get<int>() : prim["attributes"][attribute].get<int>();
  }
  // Byte offset of element `element` (component `component`, 4-byte components) in the .bin.
  size_t byte_offset(int accessor_index, size_t element, size_t components, size_t component) const {
    const json& acc = doc["accessors"][static_cast<size_t>(accessor_index)];
    const json& view = doc["bufferViews"][acc["bufferView"].get<size_t>()];
    return view.value("byteOffset", size_t{0}) + acc.value("byteOffset", size_t{0}) +
           (element * components + component) * 4;
  }
  // Appends `bytes` to the .bin (4-byte aligned, as glTF asks of vertex data) and
  // returns where they start; buffer 0's byteLength follows (save_json() to keep it).
  size_t append_bin(const std::string& bytes) {
    std::string data = kit::test::read_file(bin);
    data.resize((data.size() + 3) / 4 * 4, '\0');
    const size_t offset = data.size();
    kit::test::write_file(bin, data + bytes);
    doc["buffers"][0]["byteLength"] = offset + bytes.size();
    return offset;
  }
  // A new bufferView over `bytes` appended to the .bin; returns its index.
  int add_view(const std::string& bytes, size_t byte_stride = 0) {
    json view = {{"buffer", 0}, {"byteOffset", append_bin(bytes)}, {"byteLength", bytes.size()}};
    if (byte_stride) view["byteStride"] = byte_stride;
    doc["bufferViews"].push_back(view);
    return static_cast<int>(doc["bufferViews"].size()) - 1;
  }
  int add_accessor(const json& accessor) {
    doc["accessors"].push_back(accessor);
    return static_cast<int>(doc["accessors"].size()) - 1;
  }
  // Every component of a tightly packed FLOAT accessor, read from the .bin as written.
  std::vector<float> floats(int accessor_index, size_t components) const {
    const std::string bytes = kit::test::read_file(bin);
    const size_t count = doc["accessors"][static_cast<size_t>(accessor_index)]["count"];
    std::vector<float> out(count * components);
    std::memcpy(out.data(), &bytes.at(byte_offset(accessor_index, 0, components, 0)), out.size() * 4);
    return out;
  }
  void require_extension(const std::string& name) {
    doc["extensionsUsed"].push_back(name);
    doc["extensionsRequired"].push_back(name);
  }

  // Overwrites 4 bytes of the .bin at `offset` with `value`'s bytes.
  template <typename T>
  void patch_bin(size_t offset, T value) const {
    static_assert(sizeof(T) == 4, "glTF components patched here are 4 bytes");
    std::string bytes = kit::test::read_file(bin);
    ASSERT_LE(offset + 4, bytes.size());
    std::memcpy(&bytes[offset], &value, 4);
    kit::test::write_file(bin, bytes);
  }
};

void expect_error(const fs::path& path, const std::string& phrase) {
  std::string message = kit::test::scene_load_error(path);
  EXPECT_NE(message.find(path.string()), std::string::npos) << "message does not name the file: " << message;
  EXPECT_NE(message.find(phrase), std::string::npos) << "expected \"" << phrase << "\" in: " << message;
}

TEST(SceneLoaderErrors, MissingFile) {
  fs::path missing = kit::test::temp_dir("scene_loader/missing") / "no_such_scene.gltf";
  expect_error(missing, "scene file not found");
}

TEST(SceneLoaderErrors, TruncatedJson) {
  SceneCopy copy("sphere", "truncated");
  std::string text = kit::test::read_file(copy.gltf);
  kit::test::write_file(copy.gltf, text.substr(0, text.size() / 2));
  expect_error(copy.gltf, "invalid glTF");
  expect_error(copy.gltf, "parse error");
}

TEST(SceneLoaderErrors, MissingBuffer) {
  SceneCopy copy("sphere", "missing_bin");
  fs::remove(copy.bin);
  expect_error(copy.gltf, "invalid glTF");
  expect_error(copy.gltf, copy.bin.filename().string());  // says which file is missing
}

TEST(SceneLoaderErrors, OutOfRangeIndex) {
  SceneCopy copy("sphere", "bad_index");
  constexpr uint32_t kBadIndex = 0x00ffffffu;
  constexpr size_t kPatchedPosition = 7;  // any index inside the list
  copy.patch_bin(copy.byte_offset(copy.accessor("indices"), kPatchedPosition, 1, 0), kBadIndex);
  expect_error(copy.gltf, "index " + std::to_string(kBadIndex) + " at position " + std::to_string(kPatchedPosition) +
                              " is out of range");
}

TEST(SceneLoaderErrors, WrongAccessorType) {
  SceneCopy copy("sphere", "vec2_position");
  copy.doc["accessors"][static_cast<size_t>(copy.accessor("POSITION"))]["type"] = "VEC2";
  copy.save_json();
  expect_error(copy.gltf, "POSITION: accessor " + std::to_string(copy.accessor("POSITION")) + " has the wrong type");
}

TEST(SceneLoaderErrors, NanPosition) {
  SceneCopy copy("sphere", "nan_position");
  constexpr size_t kVertex = 40;
  copy.patch_bin(copy.byte_offset(copy.accessor("POSITION"), kVertex, 3, 1), std::numeric_limits<float>::quiet_NaN());
  expect_error(copy.gltf, "POSITION " + std::to_string(kVertex) + " is not finite");
}

TEST(SceneLoaderErrors, NegativeLightRange) {
  SceneCopy copy("sphere", "negative_range");
  copy.doc["extensions"]["KHR_lights_punctual"]["lights"][0]["range"] = -2.0;
  copy.save_json();
  expect_error(copy.gltf, "KHR_lights_punctual light 0 has range -2");
}

// A range in the file reaches the Light (lab 3's window, lights.glsl kit_range_window).
TEST(SceneLoaderValid, LightRangeIsLoaded) {
  SceneCopy copy("sphere", "light_range");
  copy.doc["extensions"]["KHR_lights_punctual"]["lights"][0]["range"] = 3.5;
  copy.save_json();
  const kit::Scene scene = kit::load_scene(copy.gltf.string());
  ASSERT_EQ(scene.lights.size(), 1u);
  EXPECT_FLOAT_EQ(scene.lights[0].range, 3.5f);
  EXPECT_EQ(kit::test::scene("sphere").lights[0].range, 0.0f) << "the kit's scenes leave range out";
}

// glTF's alphaMode, alphaCutoff and doubleSided reach Material; absent, they are
// glTF's defaults (OPAQUE, 0.5, single-sided). An unknown mode is drawn as OPAQUE, with a warning.
TEST(SceneLoaderValid, AlphaModeCutoffAndDoubleSidedAreLoaded) {
  const kit::Scene& scene = kit::test::scene("materials");
  auto material = [&](const std::string& name) -> const kit::Material& {
    for (const kit::Material& m : scene.materials)
      if (m.name == name) return m;
    throw std::runtime_error("no material " + name);
  };
  EXPECT_EQ(material("masked_ramp").alpha_mode, KIT_ALPHA_MASK);
  EXPECT_FLOAT_EQ(material("masked_ramp").alpha_cutoff, 0.3f);
  EXPECT_FALSE(material("masked_ramp").double_sided);
  EXPECT_EQ(material("blend_half").alpha_mode, KIT_ALPHA_BLEND);
  EXPECT_TRUE(material("double_sided_yellow").double_sided);
  EXPECT_EQ(material("double_sided_yellow").alpha_mode, KIT_ALPHA_OPAQUE);
  EXPECT_FLOAT_EQ(material("double_sided_yellow").alpha_cutoff, 0.5f);

  SceneCopy copy("sphere", "alpha_mode_unknown");
  copy.doc["materials"][0]["alphaMode"] = "CUTOUT";
  copy.save_json();
  const kit::Scene unknown = kit::load_scene(copy.gltf.string());
  EXPECT_EQ(unknown.materials.at(0).alpha_mode, KIT_ALPHA_OPAQUE);
  ASSERT_FALSE(unknown.warnings.empty());
  EXPECT_NE(unknown.warnings.back().find("alphaMode 'CUTOUT'"), std::string::npos) << unknown.warnings.back();
}

TEST(SceneLoaderErrors, AccessorPastTheEndOfItsBuffer) {
  SceneCopy copy("sphere", "short_view");
  size_t position = static_cast<size_t>(copy.accessor("POSITION"));
  copy.doc["accessors"][position]["count"] = copy.doc["accessors"][position]["count"].get<size_t>() * 4;
  copy.save_json();
  expect_error(copy.gltf, "reads past the end of its buffer");
}

// ---- hostile files: each would crash, hang or read outside the scene before ----

// The bounds check the loader used to make, in size_t as it made it: it wraps.
size_t naive_accessor_end(size_t byte_offset, size_t stride, size_t count, size_t element) {
  return byte_offset + stride * (count - 1) + element;
}

TEST(SceneLoaderHostile, AccessorCountThatWrapsTheBoundsCheckIsRefused) {
  SceneCopy copy("sphere", "wrapping_count");
  size_t position = static_cast<size_t>(copy.accessor("POSITION"));
  const size_t count = (size_t{1} << 62) + 1;  // 12 * (count - 1) + 12 wraps to 12
  const size_t view_length = copy.doc["bufferViews"][copy.doc["accessors"][position]["bufferView"].get<size_t>()]["byteLength"];
  // Witness: the old check passed this accessor (and the read loop then wrote past its vector).
  EXPECT_LE(naive_accessor_end(0, 12, count, 12), view_length);
  copy.doc["accessors"][position]["count"] = count;
  copy.save_json();
  expect_error(copy.gltf, "reads past the end of its buffer");
}

TEST(SceneLoaderHostile, ByteOffsetNearTwoToThe64IsRefused) {
  SceneCopy copy("sphere", "huge_offset");
  size_t position = static_cast<size_t>(copy.accessor("POSITION"));
  const size_t offset = ~size_t{0} - 7;  // view offset + this wraps to just before the buffer
  const size_t count = copy.doc["accessors"][position]["count"];
  EXPECT_LT(naive_accessor_end(offset, 12, count, 12), offset) << "witness: the old sum wraps";
  copy.doc["accessors"][position]["byteOffset"] = offset;
  copy.save_json();
  expect_error(copy.gltf, "byteOffset");
}

TEST(SceneLoaderHostile, DeeplyNestedJsonIsRefusedBeforeParsing) {
  SceneCopy copy("sphere", "deep_json");
  std::string text = kit::test::read_file(copy.gltf);
  const size_t depth = 100000;  // tinygltf's recursive parser runs off the stack at this depth
  std::string deep = "\"extras\": " + std::string(depth, '[') + std::string(depth, ']') + ",";
  text.insert(text.find('{') + 1, deep);
  kit::test::write_file(copy.gltf, text);
  expect_error(copy.gltf, "nested deeper than 64");
  // The limit refuses nothing a real file does: 60 levels load.
  SceneCopy ok("sphere", "deep_json_ok");
  std::string fine = kit::test::read_file(ok.gltf);
  fine.insert(fine.find('{') + 1, "\"extras\": " + std::string(58, '[') + std::string(58, ']') + ",");
  kit::test::write_file(ok.gltf, fine);
  EXPECT_NO_THROW(kit::load_scene(ok.gltf.string()));
}

TEST(SceneLoaderHostile, BufferThatIsAFifoFailsAtOnce) {
  SceneCopy copy("sphere", "fifo");
  fs::remove(copy.bin);
  ASSERT_EQ(mkfifo(copy.bin.c_str(), 0600), 0);  // opening it for reading would wait for a writer forever
  std::string message = kit::test::scene_load_error(copy.gltf);
  EXPECT_NE(message.find("not a regular file"), std::string::npos) << message;
  EXPECT_NE(message.find(copy.gltf.string()), std::string::npos) << message;
}

TEST(SceneLoaderHostile, NodeGraphThatDoublesAtEachLevelIsRefused) {
  SceneCopy copy("sphere", "doubling_nodes");
  // 40 nodes, each listing the next one twice: 2^40 visits for a walk that does not
  // remember where it has been, though the depth (40) is within any depth limit.
  const int levels = 40;
  json nodes = json::array();
  for (int i = 0; i < levels; ++i) {
    json node = {{"name", "n" + std::to_string(i)}};
    if (i + 1 < levels) node["children"] = {i + 1, i + 1};
    else node["mesh"] = 0;
    nodes.push_back(node);
  }
  copy.doc["nodes"] = nodes;
  copy.doc["scenes"] = json::array({{{"nodes", {0}}}});
  copy.doc["scene"] = 0;
  copy.doc.erase("cameras");
  copy.save_json();
  double naive_visits = std::pow(2.0, levels - 1);
  EXPECT_GT(naive_visits, 1e11) << "witness: the old walk's work";
  expect_error(copy.gltf, "reached twice");
}

TEST(SceneLoaderHostile, UrisOutsideTheSceneFolderAreRefused) {
  SceneCopy copy("sphere", "escape/inner");
  fs::path outside = copy.dir.parent_path() / "outside.bin";
  fs::copy_file(copy.bin, outside, fs::copy_options::overwrite_existing);
  copy.doc["buffers"][0]["uri"] = "../outside.bin";
  copy.save_json();
  expect_error(copy.gltf, "outside the scene's folder");
  copy.doc["buffers"][0]["uri"] = fs::absolute(outside).string();
  copy.save_json();
  expect_error(copy.gltf, "outside the scene's folder");
  // A link inside the folder that points out of it is refused too.
  fs::create_symlink(outside, copy.dir / "link.bin");
  copy.doc["buffers"][0]["uri"] = "link.bin";
  copy.save_json();
  expect_error(copy.gltf, "symbolic link");
}

// ---- glTF core features beyond the kit's own scenes ----

TEST(SceneLoaderGltf, RequiredExtensionTheKitLacksIsRefusedByName) {
  SceneCopy copy("sphere", "required_extension");
  copy.doc["extensionsUsed"] = {"EXT_meshopt_compression"};
  copy.save_json();
  EXPECT_NO_THROW(kit::load_scene(copy.gltf.string())) << "witness: merely used, it loads";
  copy.doc["extensionsRequired"] = {"EXT_meshopt_compression"};
  copy.save_json();
  expect_error(copy.gltf, "requires the glTF extension EXT_meshopt_compression");
}

TEST(SceneLoaderGltf, PointsAndLinesAreLeftOutWithAWarning) {
  SceneCopy copy("sphere", "points");
  json points = copy.doc["meshes"][0]["primitives"][0];
  points["mode"] = 0;  // POINTS
  copy.doc["meshes"][0]["primitives"].push_back(points);
  copy.save_json();
  const kit::Scene triangles = kit::load_scene(kit::resolve_scene("sphere"));
  const kit::Scene scene = kit::load_scene(copy.gltf.string());
  EXPECT_EQ(scene.draws.size(), triangles.draws.size());
  ASSERT_EQ(scene.warnings.size(), 1u);
  EXPECT_NE(scene.warnings[0].find("mode 0 (points or lines) is not drawn"), std::string::npos) << scene.warnings[0];
}

// No NORMAL: each triangle gets its plane's normal, in double from the JSON's positions.
TEST(SceneLoaderGltf, MissingNormalsAreFlatNormals) {
  SceneCopy copy("sphere", "flat_normals");
  json& prim = copy.doc["meshes"][0]["primitives"][0];
  prim["attributes"].erase("NORMAL");
  copy.save_json();
  const kit::Scene scene = kit::load_scene(copy.gltf.string());
  const kit::Primitive& p = scene.primitives.at(0);
  const kit::Scene source = kit::load_scene(kit::resolve_scene("sphere"));
  const kit::Primitive& indexed = source.primitives.at(0);
  ASSERT_EQ(p.indices.size(), indexed.indices.size());
  ASSERT_EQ(p.vertices.size(), p.indices.size()) << "one vertex per triangle corner";
  size_t checked = 0;
  for (size_t t = 0; t + 2 < indexed.indices.size(); t += 3) {
    glm::dvec3 a(indexed.vertices[indexed.indices[t]].position), b(indexed.vertices[indexed.indices[t + 1]].position),
        c(indexed.vertices[indexed.indices[t + 2]].position);
    glm::dvec3 n = glm::cross(b - a, c - a);
    if (glm::length(n) < 1e-9) continue;  // degenerate (the sphere's poles)
    n = glm::normalize(n);
    for (int k = 0; k < 3; ++k) {
      const kit::Vertex& v = p.vertices[p.indices[t + static_cast<size_t>(k)]];
      EXPECT_NEAR(glm::distance(glm::dvec3(v.position), k == 0 ? a : k == 1 ? b : c), 0.0, 1e-9);
      EXPECT_NEAR(glm::distance(glm::dvec3(v.normal), n), 0.0, kUnitTolerance) << "triangle " << t / 3;
    }
    ++checked;
  }
  EXPECT_GT(checked, indexed.indices.size() / 3 / 2);
}

TEST(SceneLoaderGltf, StripsAndFansBecomeTriangleLists) {
  SceneCopy copy("sphere", "strip");
  // A strip over the first primitive's first 5 indices: triangles (0,1,2), (2,1,3), (2,3,4).
  const kit::Scene source = kit::load_scene(kit::resolve_scene("sphere"));
  copy.doc["meshes"][0]["primitives"][0]["mode"] = 5;  // TRIANGLE_STRIP
  copy.save_json();
  const kit::Scene strip = kit::load_scene(copy.gltf.string());
  const std::vector<uint32_t>& in = source.primitives.at(0).indices;
  const std::vector<uint32_t>& out = strip.primitives.at(0).indices;
  ASSERT_EQ(out.size(), 3 * (in.size() - 2));
  EXPECT_EQ(std::vector<uint32_t>(out.begin(), out.begin() + 9),
            (std::vector<uint32_t>{in[0], in[1], in[2], in[2], in[1], in[3], in[2], in[3], in[4]}));
  copy.doc["meshes"][0]["primitives"][0]["mode"] = 6;  // TRIANGLE_FAN
  copy.save_json();
  const kit::Scene fan = kit::load_scene(copy.gltf.string());
  const std::vector<uint32_t>& f = fan.primitives.at(0).indices;
  EXPECT_EQ(std::vector<uint32_t>(f.begin(), f.begin() + 6), (std::vector<uint32_t>{in[0], in[1], in[2], in[0], in[2], in[3]}));
}

// A node's light index is checked before it becomes an int: tinygltf's
// GetNumberAsInt converted 1e300 to int, undefined behaviour that UBSan reported
// (an input written for the fuzz harnesses). Not a whole number naming a light: refused.
TEST(SceneLoaderHostile, LightIndexThatIsNoLightIsRefused) {
  SceneCopy copy("sphere", "light_index");
  json* light_node = nullptr;
  for (json& node : copy.doc["nodes"])
    if (node.contains("extensions") && node["extensions"].contains("KHR_lights_punctual")) light_node = &node;
  ASSERT_NE(light_node, nullptr) << "the sphere scene has a light";
  json& index = (*light_node)["extensions"]["KHR_lights_punctual"]["light"];
  const std::pair<json, std::string> cases[] = {
      {1e300, "light index 1e+300 does not exist"}, {-1e300, "light index -1e+300 does not exist"},
      {4294967296.0, "light index 4.29497e+09 does not exist"}, {0.5, "light index 0.5 does not exist"},
      {1, "light index 1 does not exist"}, {-1, "light index -1 does not exist"},
      {"0", "light index (not a number) does not exist"},
  };
  for (const auto& [value, phrase] : cases) {
    index = value;
    copy.save_json();
    expect_error(copy.gltf, "KHR_lights_punctual " + phrase);
  }
  index = 0.0;  // a whole number written as a real is still light 0
  copy.save_json();
  EXPECT_EQ(kit::load_scene(copy.gltf.string()).lights.size(), 1u);
}

// ---- accessor layouts: strides, sparse accessors, integer components ----

template <typename T>
std::string bytes_of(const std::vector<T>& values) {
  return std::string(reinterpret_cast<const char*>(values.data()), values.size() * sizeof(T));
}

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
  expect_error(copy.gltf, "POSITION: accessor " + std::to_string(position) + ": sparse index " + std::to_string(count) +
                              " at position 1 is out of range");
  // A sparse count beyond the accessor's, whose indices would run past their view.
  copy.doc["accessors"][static_cast<size_t>(position)]["sparse"]["count"] = count + 1;
  copy.save_json();
  expect_error(copy.gltf, "sparse count " + std::to_string(count + 1) + " is not between 1 and");
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
    expect_error(copy.gltf, "NORMAL: accessor " + std::to_string(attributes["NORMAL"].get<int>()) +
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
  expect_error(copy.gltf, "POSITION: accessor " + std::to_string(attributes["POSITION"].get<int>()) +
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
  expect_error(copy.gltf, where + std::to_string(attributes["COLOR_0"].get<int>()) + " is VEC2; COLOR_0 must be VEC3 or VEC4");
  attributes["COLOR_0"] = add_integer_accessor(copy, bytes, count, 4, 5121, false);
  copy.save_json();
  expect_error(copy.gltf, where + std::to_string(attributes["COLOR_0"].get<int>()) +
                              " has an unsupported component type UNSIGNED_BYTE");
  const std::vector<int8_t> signed_bytes = {-5, 100};
  attributes["COLOR_0"] = add_integer_accessor(copy, signed_bytes, count, 4, 5120, true);
  copy.save_json();
  expect_error(copy.gltf, where + std::to_string(attributes["COLOR_0"].get<int>()) +
                              " has an unsupported component type normalized BYTE");
  // KHR_mesh_quantization widens POSITION, NORMAL, TANGENT and TEXCOORD, not COLOR_0.
  copy.require_extension("KHR_mesh_quantization");
  copy.save_json();
  expect_error(copy.gltf, "unsupported component type normalized BYTE");

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

// ---- mirrored transforms ----

TEST(SceneLoaderMirrored, NegativeDeterminantMarksTheDrawMirrored) {
  SceneCopy copy("sphere", "mirrored");
  copy.doc["nodes"][0]["scale"] = {-1.0, 1.0, 1.0};
  copy.save_json();
  EXPECT_FALSE(kit::test::scene("sphere").draws.at(0).mirrored());
  EXPECT_TRUE(kit::load_scene(copy.gltf.string()).draws.at(0).mirrored());
  // Mirrored twice (a parent mirroring in y over the child mirroring in x): not mirrored.
  copy.doc["nodes"].push_back({{"name", "mirror_parent"}, {"scale", {1.0, -1.0, 1.0}}, {"children", {0}}});
  copy.doc["scenes"][0]["nodes"][0] = copy.doc["nodes"].size() - 1;
  copy.save_json();
  EXPECT_FALSE(kit::load_scene(copy.gltf.string()).draws.at(0).mirrored());
}

// Pixels the geometry pass covers (depth below the clear value 1) for a 1 m quad
// at the origin, seen from +Z (stage 1, the reference solution's shaders).
size_t covered_pixels(const kit::Primitive& quad, const glm::mat4& world) {
  kit::test::context();
  const kit::Scene scene = kit::test::tiny_scene({quad}, {kit::test::plain_material(0.5f)}, {{0, world}}, {});
  kit::RenderSettings settings;
  settings.width = settings.height = 32;
  const kit::Stage& stage = kit::find_stage("gbuffer");
  kit::Renderer renderer(stage, kit::stage_library(stage, kit::kit_root() / "solutions"), scene, settings);
  kit::Camera camera;
  camera.position = {0.0f, 0.0f, 3.0f};
  camera.view = glm::lookAt(camera.position, glm::vec3(0.0f), glm::vec3(0, 1, 0));
  renderer.render(kit::frame_camera(camera, 1.0f));
  GLint front_face = 0;
  glGetIntegerv(GL_FRONT_FACE, &front_face);
  EXPECT_EQ(front_face, GL_CCW) << "draw_scene restores GL's default winding";
  const kit::Image depth = renderer.read_view(kit::View::Depth, true);
  return static_cast<size_t>(std::count_if(depth.pixels.begin(), depth.pixels.end(), [](float d) { return d < 1.0f; }));
}

TEST(SceneLoaderMirrored, MirroredQuadStillFacesTheCamera) {
  const kit::Primitive quad = kit::test::quad_primitive({1, 0, 0}, {0, 1, 0}, {1, 1});  // front face looks along +Z
  const size_t plain = covered_pixels(quad, glm::mat4(1.0f));
  EXPECT_GT(plain, 0u);
  // Witness that back faces are culled: the quad turned away covers nothing.
  EXPECT_EQ(covered_pixels(kit::test::quad_primitive({-1, 0, 0}, {0, 1, 0}, {1, 1}), glm::mat4(1.0f)), 0u);
  // Mirrored in x it still faces +Z, its triangles now clockwise on screen: drawn, all of it.
  const glm::mat4 mirror = glm::scale(glm::mat4(1.0f), glm::vec3(-1.0f, 1.0f, 1.0f));
  EXPECT_EQ(covered_pixels(quad, mirror), plain);
}

// ---- valid scenes ----

// glTF node local matrix (matrix, or T * R * S) in double.
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

// World matrix of every node, by name, walking the default scene from its roots.
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

json scene_json(const std::string& name) { return json::parse(kit::test::read_file(kit::resolve_scene(name))); }

KIT_NO_DANGLING const kit::Primitive& primitive_named(const kit::Scene& scene, const std::string& mesh_name) {
  for (const kit::Primitive& p : scene.primitives)
    if (p.name.find("('" + mesh_name + "')") != std::string::npos) return p;
  throw std::runtime_error("no primitive of mesh '" + mesh_name + "' in " + scene.path);
}

void expect_matrix_near(const glm::mat4& actual, const glm::dmat4& expected, const std::string& what) {
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r)
      EXPECT_NEAR(actual[c][r], expected[c][r], kMatrixTolerance) << what << " [" << c << "][" << r << "]";
}

// Every draw's world matrix is parent x local along the node path, as in the JSON.
void expect_draw_transforms_match_json(const std::string& scene_name) {
  const kit::Scene& scene = kit::test::scene(scene_name);
  json doc = scene_json(scene_name);
  std::map<std::string, glm::dmat4> worlds = world_matrices(doc);
  size_t expected_draws = 0;
  for (const json& node : doc["nodes"]) {
    if (!node.contains("mesh")) continue;
    const json& mesh = doc["meshes"][node["mesh"].get<size_t>()];
    expected_draws += mesh["primitives"].size();
    const std::string mesh_name = mesh["name"];
    bool found = false;
    for (const kit::DrawItem& d : scene.draws) {
      if (scene.primitives[static_cast<size_t>(d.primitive)].name.find("('" + mesh_name + "')") == std::string::npos) continue;
      expect_matrix_near(d.world, worlds.at(node["name"]), scene_name + " node " + node["name"].get<std::string>());
      found = true;
    }
    EXPECT_TRUE(found) << "no draw for node " << node["name"];
  }
  EXPECT_EQ(scene.draws.size(), expected_draws) << scene_name;
}

TEST(SceneLoaderValid, DefaultSceneCountsLightsAndCamera) {
  const kit::Scene& scene = kit::test::scene("default");
  json doc = scene_json("default");
  EXPECT_EQ(scene.primitives.size(), doc["meshes"].size());  // one primitive per kit mesh
  EXPECT_EQ(scene.materials.size(), doc["materials"].size());
  EXPECT_EQ(scene.images.size(), doc["images"].size());

  const json& lights = doc["extensions"]["KHR_lights_punctual"]["lights"];
  ASSERT_EQ(scene.lights.size(), 4u);
  ASSERT_EQ(lights.size(), 4u);
  int spots = 0;
  std::map<std::string, glm::dmat4> worlds = world_matrices(doc);
  for (size_t i = 0; i < scene.lights.size(); ++i) {
    const kit::Light& l = scene.lights[i];
    const json& expected = lights[i];  // light nodes are in light order in the kit scenes
    glm::dvec3 position(worlds.at(expected["name"])[3]);
    EXPECT_NEAR(glm::distance(glm::dvec3(l.position), position), 0.0, kMatrixTolerance) << expected["name"];
    EXPECT_NEAR(l.intensity, expected["intensity"].get<double>(), 1e-6);
    EXPECT_NEAR(l.range, expected.value("range", 0.0), 1e-6);
    if (expected["type"] == "spot") {
      ++spots;
      EXPECT_EQ(l.type, KIT_LIGHT_SPOT);
      EXPECT_NEAR(l.inner_cone, expected["spot"]["innerConeAngle"].get<double>(), 1e-6);
      EXPECT_NEAR(l.outer_cone, expected["spot"]["outerConeAngle"].get<double>(), 1e-6);
      // The generator aims the spot from (0, 3.5, 6) at (0, 0.95, -1): the node's -Z.
      glm::dvec3 aim = glm::normalize(glm::dvec3(0.0, 0.95, -1.0) - position);
      EXPECT_NEAR(glm::distance(glm::dvec3(l.direction), aim), 0.0, kUnitTolerance);
    } else {
      EXPECT_EQ(l.type, KIT_LIGHT_POINT);
    }
  }
  EXPECT_EQ(spots, 1);

  ASSERT_TRUE(scene.camera.has_value());
  const json& cam = doc["cameras"][0]["perspective"];
  EXPECT_NEAR(scene.camera->yfov, cam["yfov"].get<double>(), 1e-6);
  EXPECT_NEAR(scene.camera->znear, cam["znear"].get<double>(), 1e-6);
  EXPECT_NEAR(scene.camera->zfar, cam["zfar"].get<double>(), 1e-6);
  glm::dvec3 eye(worlds.at("camera")[3]);
  EXPECT_NEAR(glm::distance(glm::dvec3(scene.camera->position), eye), 0.0, kMatrixTolerance);
  // The camera looks from (0, 2.2, 6.5) at (0, 0.8, -1): view * eye = origin, forward = -Z.
  glm::dvec4 eye_in_view = glm::dmat4(scene.camera->view) * glm::dvec4(eye, 1.0);
  EXPECT_NEAR(glm::length(glm::dvec3(eye_in_view)), 0.0, kMatrixTolerance);
  glm::dvec3 forward(glm::inverse(glm::dmat4(scene.camera->view)) * glm::dvec4(0, 0, -1, 0));
  EXPECT_NEAR(glm::distance(forward, glm::normalize(glm::dvec3(0.0, 0.8, -1.0) - eye)), 0.0, kUnitTolerance);
}

// The sphere scene's light made a KHR_lights_punctual "directional" light on a
// rotated node under a rotated, non-uniformly scaled parent, with its light, node
// and parent node returned for a test to change.
struct DirectionalCopy {
  SceneCopy copy;
  json* light = nullptr;
  std::string node_name;
  explicit DirectionalCopy(const std::string& case_name) : copy("sphere", case_name) {
    light = &copy.doc["extensions"]["KHR_lights_punctual"]["lights"][0];
    (*light)["type"] = "directional";
    size_t node_index = 0;
    for (size_t i = 0; i < copy.doc["nodes"].size(); ++i)
      if (copy.doc["nodes"][i].contains("extensions") && copy.doc["nodes"][i]["extensions"].contains("KHR_lights_punctual"))
        node_index = i;
    json& node = copy.doc["nodes"][node_index];
    node_name = node.value("name", "");
    // 50 degrees about (1, 2, 0.5) / |.|, as glTF's x, y, z, w.
    const glm::dquat own = glm::angleAxis(glm::radians(50.0), glm::normalize(glm::dvec3(1.0, 2.0, 0.5)));
    node["rotation"] = {own.x, own.y, own.z, own.w};
    const glm::dquat parent = glm::angleAxis(glm::radians(110.0), glm::dvec3(0.0, 1.0, 0.0));
    copy.doc["nodes"].push_back({{"name", "sun_parent"},
                                 {"translation", {3.0, -1.0, 2.0}},
                                 {"rotation", {parent.x, parent.y, parent.z, parent.w}},
                                 {"scale", {2.0, 0.5, 1.5}},
                                 {"children", {node_index}}});
    for (json& root : copy.doc["scenes"][0]["nodes"])
      if (root.get<size_t>() == node_index) root = copy.doc["nodes"].size() - 1;
  }
};

// A directional light is lit (it was dropped before): its direction is its node's
// world -Z, computed here in double through the whole node tree; its intensity is
// the file's (lux) and its range, which glTF says does not apply, is left out.
TEST(SceneLoaderValid, DirectionalLightGetsItsNodesWorldDirection) {
  DirectionalCopy sun("directional_rotated");
  (*sun.light)["intensity"] = 3.25;
  (*sun.light)["color"] = {1.0, 0.8, 0.6};
  (*sun.light)["range"] = 7.0;
  sun.copy.save_json();
  const kit::Scene scene = kit::load_scene(sun.copy.gltf.string());
  ASSERT_EQ(scene.lights.size(), 1u);
  const kit::Light& l = scene.lights[0];
  EXPECT_EQ(l.type, KIT_LIGHT_DIRECTIONAL);
  const glm::dmat4 world = world_matrices(sun.copy.doc).at(sun.node_name);
  const glm::dvec3 expected = glm::normalize(glm::dvec3(world * glm::dvec4(0.0, 0.0, -1.0, 0.0)));
  EXPECT_GT(glm::distance(expected, glm::dvec3(0.0, 0.0, -1.0)), 0.5) << "the rotations must move -Z";
  EXPECT_NEAR(glm::distance(glm::dvec3(l.direction), expected), 0.0, kUnitTolerance);
  EXPECT_NEAR(glm::length(glm::dvec3(l.direction)), 1.0, kUnitTolerance);
  EXPECT_NEAR(l.intensity, 3.25, 1e-6);
  EXPECT_NEAR(glm::distance(glm::dvec3(l.color), glm::dvec3(1.0, 0.8, 0.6)), 0.0, 1e-6);
  EXPECT_EQ(l.range, 0.0f) << "range does not apply to a directional light";
}

// A directional light's values are checked as a point or spot light's are, and
// a node scaled to nothing gives it no direction.
TEST(SceneLoaderErrors, InvalidDirectionalLightIsRefused) {
  {
    DirectionalCopy sun("directional_negative_range");
    (*sun.light)["range"] = -1.0;
    sun.copy.save_json();
    expect_error(sun.copy.gltf, "KHR_lights_punctual light 0 has range -1");
  }
  {
    DirectionalCopy sun("directional_negative_intensity");
    (*sun.light)["intensity"] = -2.0;
    sun.copy.save_json();
    expect_error(sun.copy.gltf, "KHR_lights_punctual light 0 has intensity -2");
  }
  {
    DirectionalCopy sun("directional_zero_scale");
    sun.copy.doc["nodes"].back()["scale"] = {0.0, 0.0, 0.0};
    sun.copy.save_json();
    expect_error(sun.copy.gltf, "KHR_lights_punctual light 0 (directional) is on a node whose transform has no -Z");
  }
  {
    DirectionalCopy sun("light_type_unknown");
    (*sun.light)["type"] = "area";
    sun.copy.save_json();
    expect_error(sun.copy.gltf, "KHR_lights_punctual light 0 has type 'area' (must be point, spot or directional)");
  }
}

TEST(SceneLoaderValid, NodeHierarchyComposesParentTimesLocal) {
  expect_draw_transforms_match_json("default");
  expect_draw_transforms_match_json("normalmap");
  const kit::Scene& scene = kit::test::scene("default");
  // sphere_rows (0, 0.5, -1) -> row_metal (0, 0.9, 0) -> sphere_gold_r50 (0, 0, 0): world (0, 1.4, -1);
  // sphere_dielectric_r0 sits at (-2, 0, 0) under row_dielectric (identity): world (-2, 0.5, -1).
  const std::pair<std::string, glm::dvec3> spheres[] = {{"sphere_gold_r50", {0.0, 1.4, -1.0}},
                                                       {"sphere_dielectric_r0", {-2.0, 0.5, -1.0}},
                                                       {"sphere_gold_r100", {2.0, 1.4, -1.0}}};
  for (const auto& [name, expected] : spheres) {
    const kit::Primitive& p = primitive_named(scene, name);
    for (const kit::DrawItem& d : scene.draws) {
      if (&scene.primitives[static_cast<size_t>(d.primitive)] != &p) continue;
      EXPECT_NEAR(glm::distance(glm::dvec3(d.world[3]), expected), 0.0, kMatrixTolerance) << name;
    }
  }
  // Non-uniform parent scale (2, 0.5, 1) over a child rotated -30 degrees about x: the order
  // matters here. parent x local sends the child's +Y to (0, 0.5 cos 30, -sin 30).
  const kit::Scene& normalmap = kit::test::scene("normalmap");
  const kit::Primitive& tilted = primitive_named(normalmap, "tilted_quad");
  for (const kit::DrawItem& d : normalmap.draws) {
    if (&normalmap.primitives[static_cast<size_t>(d.primitive)] != &tilted) continue;
    glm::dvec3 up(glm::dmat4(d.world) * glm::dvec4(0, 1, 0, 0));
    EXPECT_NEAR(glm::distance(up, glm::dvec3(0.0, 0.5 * std::cos(glm::radians(30.0)), -std::sin(glm::radians(30.0)))), 0.0,
                kMatrixTolerance);
  }
}

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

kit::Vertex vertex(glm::vec3 p, glm::vec3 n, glm::vec2 uv) { return {p, n, uv, glm::vec2(0.0f), glm::vec4(0.0f)}; }

void expect_valid_frame(const std::vector<kit::Vertex>& vertices, const std::string& what) {
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

// ---- EXT_mesh_gpu_instancing ----

TEST(SceneLoaderInstancing, EachInstanceIsADrawAtNodeTimesInstanceTrs) {
  SceneCopy copy("sphere", "instancing");
  const std::vector<float> translations = {0, 0, 0, 3, 0, -1, -2.5f, 1, 4};
  const std::vector<float> rotations = {0, 0, 0, 1, 0, 0.70710678f, 0, 0.70710678f, 0.5f, 0.5f, 0.5f, 0.5f};
  const std::vector<float> scales = {1, 1, 1, 2, 2, 2, 0.5f, 1, 3};
  auto accessor = [&](const std::vector<float>& values, const char* type) {
    const size_t components = std::string(type) == "VEC4" ? 4 : 3;
    return copy.add_accessor({{"bufferView", copy.add_view(bytes_of(values))}, {"componentType", 5126},
                              {"count", values.size() / components}, {"type", type}});
  };
  json& node = copy.doc["nodes"][0];
  node["translation"] = {1.0, 2.0, 3.0};
  node["rotation"] = {0.0, 0.0, 0.38268343, 0.92387953};  // 45 degrees about z
  node["extensions"]["EXT_mesh_gpu_instancing"]["attributes"] = {
      {"TRANSLATION", accessor(translations, "VEC3")}, {"ROTATION", accessor(rotations, "VEC4")},
      {"SCALE", accessor(scales, "VEC3")}};
  copy.require_extension("EXT_mesh_gpu_instancing");
  copy.save_json();
  const kit::Scene scene = kit::load_scene(copy.gltf.string());
  ASSERT_EQ(scene.draws.size(), 3u);
  const glm::dmat4 node_world = world_matrices(copy.doc).at("sphere");
  for (size_t i = 0; i < 3; ++i) {
    const json instance = {{"translation", {translations[3 * i], translations[3 * i + 1], translations[3 * i + 2]}},
                           {"rotation", {rotations[4 * i], rotations[4 * i + 1], rotations[4 * i + 2], rotations[4 * i + 3]}},
                           {"scale", {scales[3 * i], scales[3 * i + 1], scales[3 * i + 2]}}};
    expect_matrix_near(scene.draws[i].world, node_world * local_matrix(instance), "instance " + std::to_string(i));
  }
}

TEST(SceneLoaderInstancing, InstancesBeyondTheDrawLimitAreRefused) {
  SceneCopy copy("sphere", "instancing_limit");
  // No bufferView: zeros, so a small file can ask for any count.
  const int translations = copy.add_accessor({{"componentType", 5126}, {"count", kit::kMaxSceneDraws + 1}, {"type", "VEC3"}});
  copy.doc["nodes"][0]["extensions"]["EXT_mesh_gpu_instancing"]["attributes"]["TRANSLATION"] = translations;
  copy.save_json();
  expect_error(copy.gltf, "node 0 ('sphere') EXT_mesh_gpu_instancing has " + std::to_string(kit::kMaxSceneDraws + 1) +
                              " instances, more than the kit draws (" + std::to_string(kit::kMaxSceneDraws) + " draws in all)");
  copy.doc["accessors"][static_cast<size_t>(translations)]["count"] = kit::kMaxSceneDraws;  // at the limit: loads
  copy.save_json();
  EXPECT_EQ(kit::load_scene(copy.gltf.string()).draws.size(), kit::kMaxSceneDraws);
}

// ---- cameras ----

// glTF 2.0's projection matrices ("Projection Matrices") in double, columns first.
glm::dmat4 perspective_projection(double aspect, double yfov, double znear, double zfar) {
  const double t = std::tan(0.5 * yfov);
  glm::dmat4 p(0.0);
  p[0][0] = 1.0 / (aspect * t);
  p[1][1] = 1.0 / t;
  p[2][2] = (zfar + znear) / (znear - zfar);
  p[2][3] = -1.0;
  p[3][2] = 2.0 * zfar * znear / (znear - zfar);
  return p;
}
glm::dmat4 orthographic_projection(double xmag, double ymag, double znear, double zfar) {
  glm::dmat4 p(0.0);
  p[0][0] = 1.0 / xmag;
  p[1][1] = 1.0 / ymag;
  p[2][2] = 2.0 / (znear - zfar);
  p[3][2] = (zfar + znear) / (znear - zfar);
  p[3][3] = 1.0;
  return p;
}

TEST(SceneLoaderCameras, EveryCameraProjectsAsTheSpecSays) {
  SceneCopy copy("sphere", "cameras");
  // The sphere's camera 0 (perspective, no aspectRatio), then one with an aspect
  // ratio and an orthographic one, on nodes after it in the node tree.
  json& cameras = copy.doc["cameras"];
  ASSERT_EQ(cameras.size(), 1u);
  ASSERT_FALSE(cameras[0]["perspective"].contains("aspectRatio"));
  cameras.push_back({{"type", "perspective"}, {"perspective", {{"yfov", 0.7}, {"aspectRatio", 2.0}, {"znear", 0.05}, {"zfar", 50.0}}}});
  cameras.push_back({{"type", "orthographic"}, {"orthographic", {{"xmag", 3.0}, {"ymag", 1.5}, {"znear", 0.0}, {"zfar", 20.0}}}});
  for (int c : {1, 2}) {
    copy.doc["nodes"].push_back({{"name", "camera" + std::to_string(c)}, {"camera", c}, {"translation", {0.0, c, 5.0}}});
    copy.doc["scenes"][0]["nodes"].push_back(copy.doc["nodes"].size() - 1);
  }
  copy.save_json();
  const kit::Scene scene = kit::load_scene(copy.gltf.string());
  ASSERT_EQ(scene.cameras.size(), 3u);
  ASSERT_TRUE(scene.camera.has_value());
  EXPECT_EQ(scene.camera->view, scene.cameras[0].view) << "the first camera stays the default";

  const double window_aspect = 1.5;
  const json& p0 = cameras[0]["perspective"];
  expect_matrix_near(scene.cameras[0].projection(static_cast<float>(window_aspect)),
                     perspective_projection(window_aspect, p0["yfov"], p0["znear"], p0["zfar"]), "camera 0 (window's aspect)");
  expect_matrix_near(scene.cameras[1].projection(static_cast<float>(window_aspect)),
                     perspective_projection(2.0, 0.7, 0.05, 50.0), "camera 1 (its aspectRatio)");
  EXPECT_TRUE(scene.cameras[2].orthographic);
  expect_matrix_near(scene.cameras[2].projection(static_cast<float>(window_aspect)),
                     orthographic_projection(3.0, 1.5, 0.0, 20.0), "camera 2 (orthographic)");
  const std::map<std::string, glm::dmat4> worlds = world_matrices(copy.doc);
  for (int c : {1, 2})
    expect_matrix_near(scene.cameras[static_cast<size_t>(c)].view, glm::inverse(worlds.at("camera" + std::to_string(c))),
                       "camera " + std::to_string(c) + " view");

  // chosen_camera: -1 is the default, N the file's camera N, past the last an error naming the count.
  EXPECT_EQ(kit::chosen_camera(scene, -1).view, scene.cameras[0].view);
  EXPECT_TRUE(kit::chosen_camera(scene, 2).orthographic);
  try {
    kit::chosen_camera(scene, 3);
    ADD_FAILURE() << "camera 3 was chosen";
  } catch (const kit::Error& e) {
    EXPECT_EQ(std::string(e.what()), copy.gltf.string() + ": camera 3 does not exist: the file has 3 cameras (0 to 2)");
  }
}

TEST(SceneLoaderCameras, InvalidCamerasAreRefusedByIndex) {
  SceneCopy copy("sphere", "bad_cameras");
  copy.doc["cameras"][0] = {{"type", "orthographic"}, {"orthographic", {{"xmag", 0.0}, {"ymag", 1.0}, {"znear", 0.1}, {"zfar", 10.0}}}};
  copy.save_json();
  expect_error(copy.gltf, "camera 0 ('') has xmag 0");
  copy.doc["cameras"][0]["orthographic"] = {{"xmag", 1.0}, {"ymag", 1.0}, {"znear", 5.0}, {"zfar", 1.0}};
  copy.save_json();
  expect_error(copy.gltf, "must be 0 <= znear < zfar");
  copy.doc["cameras"][0] = {{"type", "perspective"}, {"perspective", {{"yfov", 0.8}, {"znear", 0.1}, {"zfar", 0.05}}}};
  copy.save_json();
  expect_error(copy.gltf, "camera 0 ('') has zfar");
}

// ---- textures ----

// Images are decoded once, by SceneGpu, and only those a material samples: an
// image whose pixel data is broken (its header intact) loads and uploads while
// nothing uses it (witness: decoding it fails), and fails SceneGpu, naming the
// file and the image, once a material samples it.
TEST(SceneLoaderTextures, UnusedImagesAreNeverDecoded) {
  SceneCopy copy("default", "unused_image");
  const std::string checker = kit::test::read_file(copy.dir / "checker.png");
  ASSERT_GT(checker.size(), 200u);
  kit::test::write_file(copy.dir / "broken.png", checker.substr(0, 100));  // signature and IHDR, no pixel data
  const size_t broken = copy.doc["images"].size();
  copy.doc["images"].push_back({{"uri", "broken.png"}});
  copy.save_json();
  {
    const kit::Scene scene = kit::load_scene(copy.gltf.string());
    ASSERT_EQ(scene.images.size(), broken + 1);
    EXPECT_THROW(kit::decode_scene_image(scene.images[broken]), kit::Error);  // the witness
    kit::test::context();
    EXPECT_NO_THROW(kit::SceneGpu gpu(scene));
  }
  copy.doc["textures"].push_back({{"source", broken}});
  copy.doc["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"] = {{"index", copy.doc["textures"].size() - 1}};
  copy.save_json();
  const kit::Scene scene = kit::load_scene(copy.gltf.string());
  try {
    kit::SceneGpu gpu(scene);
    ADD_FAILURE() << "a broken image a material uses was uploaded";
  } catch (const kit::Error& e) {
    EXPECT_NE(std::string(e.what()).find(copy.gltf.string() + ": image " + std::to_string(broken) + " ('broken.png')"),
              std::string::npos) << e.what();
  }
}

// Each image is uploaded in the format its material slots read it in, and only that
// one: base colour sRGB (decoded to linear by the sampler), normal maps linear.
TEST(SceneLoaderTextures, EachImageIsUploadedInTheFormatItsSlotsNeed) {
  const kit::Scene scene = kit::load_scene(kit::resolve_scene("normalmap"));
  kit::test::context();
  const kit::SceneGpu gpu(scene);
  size_t checked = 0;
  for (const kit::Material& m : scene.materials) {
    for (int image : {m.texture(KIT_UNIT_BASE_COLOR).image, m.texture(KIT_UNIT_NORMAL_MAP).image}) {
      if (image < 0) continue;
      const bool srgb = image == m.texture(KIT_UNIT_BASE_COLOR).image;
      EXPECT_NE(gpu.texture(image, srgb).id(), 0u) << "image " << image;
      EXPECT_EQ(gpu.texture(image, !srgb).id(), 0u) << "image " << image << " was also uploaded in the other format";
      ++checked;
    }
  }
  EXPECT_GT(checked, 0u);
}

// Textures of at least kLargeTextureTexels are uploaded with their CPU-made mip chain,
// as S3TC blocks (BC1 opaque, BC3 with alpha; sRGB formats for colour) when compression
// is on; normal maps and smaller textures (every kit scene's) stay RGBA8. Auto leaves
// these textures (16 MiB with their mips) uncompressed on llvmpipe: under the budget.
TEST(SceneLoaderTextures, LargeTexturesAreCompressedSmallOnesAndNormalMapsNot) {
  constexpr GLenum kSrgbDxt1 = 0x8C4C, kSrgbAlphaDxt5 = 0x8C4F;  // GL_COMPRESSED_SRGB(_ALPHA)_S3TC_DXT1/5_EXT
  constexpr int kLarge = 1024, kSmall = 256;
  auto image = [](const char* what, int side, unsigned char alpha) {
    kit::ImageRgba8 pixels{side, side, std::vector<unsigned char>(static_cast<size_t>(side) * static_cast<size_t>(side) * 4, 200)};
    for (size_t i = 3; i < pixels.pixels.size(); i += 4) pixels.pixels[i] = alpha;
    return kit::SceneImage{what, side, side, {}, pixels};
  };
  kit::Material opaque = kit::test::plain_material(0.5f), translucent = opaque, small = opaque;
  opaque.texture(KIT_UNIT_BASE_COLOR).image = 0;
  opaque.texture(KIT_UNIT_NORMAL_MAP).image = 3;
  translucent.texture(KIT_UNIT_BASE_COLOR).image = 1;
  small.texture(KIT_UNIT_BASE_COLOR).image = 2;
  kit::Primitive quad = kit::test::quad_primitive({1, 0, 0}, {0, 1, 0}, {1, 1});
  quad.material = 0;
  kit::Scene scene = kit::test::tiny_scene({quad}, {opaque, translucent, small}, {{0, glm::mat4(1.0f)}}, {});
  scene.images = {image("opaque", kLarge, 255), image("translucent", kLarge, 128), image("small", kSmall, 255),
                  image("normals", kLarge, 255)};
  kit::test::context();
  auto level_format = [](const kit::Texture2D& texture, int level) {
    GLint format = 0;
    glBindTexture(GL_TEXTURE_2D, texture.id());
    glGetTexLevelParameteriv(GL_TEXTURE_2D, level, GL_TEXTURE_INTERNAL_FORMAT, &format);
    return static_cast<GLenum>(format);
  };
  const int last_level = 10;  // 1024 -> 1x1
  {
    const kit::SceneGpu gpu(scene, kit::TextureCompression::On);
    EXPECT_TRUE(gpu.texture_compression().compress) << gpu.texture_compression().reason;
    EXPECT_EQ(level_format(gpu.texture(0, true), 0), kSrgbDxt1);
    EXPECT_EQ(level_format(gpu.texture(0, true), last_level), kSrgbDxt1);
    EXPECT_EQ(level_format(gpu.texture(1, true), 0), kSrgbAlphaDxt5);
    EXPECT_EQ(level_format(gpu.texture(2, true), 0), static_cast<GLenum>(GL_SRGB8_ALPHA8));
    EXPECT_EQ(level_format(gpu.texture(3, false), 0), static_cast<GLenum>(GL_RGBA8));
    EXPECT_EQ(level_format(gpu.texture(3, false), last_level), static_cast<GLenum>(GL_RGBA8));
  }
  const kit::SceneGpu uncompressed(scene, kit::TextureCompression::Off);
  EXPECT_EQ(level_format(uncompressed.texture(0, true), 0), static_cast<GLenum>(GL_SRGB8_ALPHA8));
  EXPECT_EQ(level_format(uncompressed.texture(0, true), last_level), static_cast<GLenum>(GL_SRGB8_ALPHA8));
  const size_t rgba8_bytes = uncompressed.texture_compression().uploaded_bytes;
  EXPECT_EQ(rgba8_bytes, uncompressed.texture_compression().uncompressed_bytes);
  EXPECT_EQ(rgba8_bytes, 3 * kit::rgba8_chain_bytes(kLarge, kLarge) + kit::rgba8_chain_bytes(kSmall, kSmall));
  const char* renderer = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
  if (kit::renders_on_cpu(renderer ? renderer : "")) {
    const kit::SceneGpu automatic(scene);
    EXPECT_FALSE(automatic.texture_compression().compress) << automatic.texture_compression().reason;
    EXPECT_EQ(level_format(automatic.texture(0, true), 0), static_cast<GLenum>(GL_SRGB8_ALPHA8));
  }
  EXPECT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));
}

// glTF samplers reach the GL sampler each material texture is drawn with; a
// texture without one gets glTF's default (repeat, trilinear for "auto").
TEST(SceneLoaderTextures, SamplersSetWrapAndFilterOfEachTexture) {
  SceneCopy copy("default", "samplers");
  ASSERT_EQ(copy.doc["textures"][0]["sampler"], 0);
  copy.doc["samplers"][0] = {{"wrapS", 33071}, {"wrapT", 33648}, {"minFilter", 9984}, {"magFilter", 9728}};
  copy.doc["samplers"].push_back({{"wrapS", 10497}});  // filters left to the implementation
  copy.doc["textures"][1]["sampler"] = 1;
  copy.doc["textures"][2].erase("sampler");
  copy.save_json();
  const kit::Scene scene = kit::load_scene(copy.gltf.string());
  ASSERT_EQ(scene.samplers.size(), 2u);
  // Which materials use which texture, from the JSON.
  std::map<int, int> sampler_of_texture = {{0, 0}, {1, 1}, {2, -1}};
  bool checked_texture[3] = {false, false, false};
  for (size_t m = 0; m < scene.materials.size(); ++m) {
    const json& base_color = copy.doc["materials"][m]["pbrMetallicRoughness"];
    if (!base_color.contains("baseColorTexture")) continue;
    const int texture = base_color["baseColorTexture"]["index"];
    EXPECT_EQ(scene.materials[m].texture(KIT_UNIT_BASE_COLOR).sampler, sampler_of_texture.at(texture))
        << "material " << m;
    checked_texture[texture] = true;
  }
  EXPECT_TRUE(checked_texture[0]) << "some material samples texture 0";

  kit::test::context();
  const kit::SceneGpu gpu(scene);
  auto parameter = [](const kit::Sampler& sampler, GLenum name) {
    GLint value = 0;
    glGetSamplerParameteriv(sampler.id(), name, &value);
    return value;
  };
  const std::pair<int, std::array<GLint, 4>> expected[] = {
      {0, {GL_CLAMP_TO_EDGE, GL_MIRRORED_REPEAT, GL_NEAREST_MIPMAP_NEAREST, GL_NEAREST}},
      {1, {GL_REPEAT, GL_REPEAT, GL_LINEAR_MIPMAP_LINEAR, GL_LINEAR}},
      {-1, {GL_REPEAT, GL_REPEAT, GL_LINEAR_MIPMAP_LINEAR, GL_LINEAR}}};
  for (const auto& [index, values] : expected) {
    const kit::Sampler& sampler = gpu.sampler(index);
    EXPECT_EQ(parameter(sampler, GL_TEXTURE_WRAP_S), values[0]) << "sampler " << index;
    EXPECT_EQ(parameter(sampler, GL_TEXTURE_WRAP_T), values[1]) << "sampler " << index;
    EXPECT_EQ(parameter(sampler, GL_TEXTURE_MIN_FILTER), values[2]) << "sampler " << index;
    EXPECT_EQ(parameter(sampler, GL_TEXTURE_MAG_FILTER), values[3]) << "sampler " << index;
  }

  copy.doc["samplers"][1]["wrapT"] = 1234;
  copy.save_json();
  expect_error(copy.gltf, "sampler 1 has wrapT 1234 (glTF allows");
}

// Drawing binds each material texture's sampler and unbinds it after, so that
// later passes sample their targets with the targets' own settings.
TEST(SceneLoaderTextures, GeometryPassLeavesNoSamplerBound) {
  const std::unique_ptr<kit::Renderer> renderer = kit::test::render_stage("gbuffer", "default");
  for (int unit : {KIT_UNIT_BASE_COLOR, KIT_UNIT_METALLIC_ROUGHNESS, KIT_UNIT_NORMAL_MAP, KIT_UNIT_EMISSIVE}) {
    glActiveTexture(GL_TEXTURE0 + static_cast<GLenum>(unit));
    GLint bound = -1;
    glGetIntegerv(GL_SAMPLER_BINDING, &bound);
    EXPECT_EQ(bound, 0) << "unit " << unit;
  }
}

// ---- UV sets and KHR_texture_transform, each texture's own ----

// The floor of the default scene: its mesh index and its material's JSON.
struct FloorOfDefaultScene {
  size_t mesh = 0;
  size_t material = 0;
  explicit FloorOfDefaultScene(const json& doc) {
    for (size_t i = 0; i < doc["meshes"].size(); ++i)
      if (doc["meshes"][i]["name"] == "floor") mesh = i;
    material = doc["meshes"][mesh]["primitives"][0]["material"];
  }
};

// A floor texture's transform is its own: the vertices keep the file's UVs, and
// TextureUv::of gives the extension's UV; the base colour's (untransformed) does not move.
TEST(SceneLoaderUv, TextureTransformBelongsToItsTexture) {
  SceneCopy copy("default", "texture_transform");
  const FloorOfDefaultScene floor(copy.doc);
  const glm::dvec2 offset(0.25, -0.5), scale(2.0, 3.0);
  const double rotation = 0.3;
  json& material = copy.doc["materials"][floor.material];
  material["emissiveTexture"] = {
      {"index", material["pbrMetallicRoughness"]["baseColorTexture"]["index"]},
      {"extensions",
       {{"KHR_texture_transform", {{"offset", {offset.x, offset.y}}, {"rotation", rotation}, {"scale", {scale.x, scale.y}}}}}}};
  copy.doc["extensionsUsed"].push_back("KHR_texture_transform");
  copy.save_json();
  const kit::Scene plain = kit::load_scene(kit::resolve_scene("default"));
  const kit::Scene moved = kit::load_scene(copy.gltf.string());
  const kit::Primitive &before = primitive_named(plain, "floor"), &after = primitive_named(moved, "floor");
  const kit::Material& m = moved.materials[static_cast<size_t>(after.material)];
  EXPECT_TRUE(moved.warnings.empty()) << moved.warnings.front();
  EXPECT_EQ(m.texture(KIT_UNIT_EMISSIVE).uv.slot, 0);
  EXPECT_EQ(m.texture(KIT_UNIT_BASE_COLOR).uv.transform, glm::mat3(1.0f));
  ASSERT_EQ(before.vertices.size(), after.vertices.size());
  size_t changed = 0;
  for (size_t i = 0; i < after.vertices.size(); ++i) {
    EXPECT_EQ(after.vertices[i].texcoord, before.vertices[i].texcoord) << "vertex " << i;
    EXPECT_EQ(m.texture(KIT_UNIT_BASE_COLOR).uv.of(after.vertices[i]), before.vertices[i].texcoord) << "vertex " << i;
    const glm::dvec2 expected = kit::test::texture_transformed(glm::dvec2(before.vertices[i].texcoord), offset, rotation, scale);
    const glm::vec2 emissive = m.texture(KIT_UNIT_EMISSIVE).uv.of(after.vertices[i]);
    EXPECT_NEAR(emissive.x, expected.x, 1e-5) << "vertex " << i;
    EXPECT_NEAR(emissive.y, expected.y, 1e-5) << "vertex " << i;
    changed += glm::distance(expected, glm::dvec2(before.vertices[i].texcoord)) > 0.01;  // ignoring it would be wrong here
  }
  EXPECT_EQ(changed, after.vertices.size());
}

// The default floor with a TEXCOORD_1 of its own (distinct from TEXCOORD_0 at every vertex).
std::vector<float> add_texcoord_1(SceneCopy& copy, const FloorOfDefaultScene& floor) {
  json& primitive = copy.doc["meshes"][floor.mesh]["primitives"][0];
  const size_t count = copy.doc["accessors"][primitive["attributes"]["POSITION"].get<size_t>()]["count"];
  std::vector<float> uv1;
  for (size_t i = 0; i < count; ++i) {
    uv1.push_back(0.125f * static_cast<float>(i) + 3.0f);
    uv1.push_back(1.0f - 0.25f * static_cast<float>(i));
  }
  const int view = copy.add_view(bytes_of(uv1));
  primitive["attributes"]["TEXCOORD_1"] =
      copy.add_accessor({{"bufferView", view}, {"componentType", 5126}, {"count", count}, {"type", "VEC2"}});
  return uv1;
}

TEST(SceneLoaderUv, EachTextureReadsTheUvSetItNames) {
  SceneCopy copy("default", "texcoord_1");
  const FloorOfDefaultScene floor(copy.doc);
  const std::vector<float> uv1 = add_texcoord_1(copy, floor);
  json& material = copy.doc["materials"][floor.material];
  material["emissiveTexture"] = {{"index", material["pbrMetallicRoughness"]["baseColorTexture"]["index"]}, {"texCoord", 1}};
  copy.save_json();
  const kit::Scene plain = kit::load_scene(kit::resolve_scene("default"));
  const kit::Scene scene = kit::load_scene(copy.gltf.string());
  const kit::Primitive& p = primitive_named(scene, "floor");
  const kit::Material& m = scene.materials[static_cast<size_t>(p.material)];
  EXPECT_EQ(m.uv_set_of_slot, (std::array<int, 2>{0, 1}));
  EXPECT_EQ(m.texture(KIT_UNIT_BASE_COLOR).uv.slot, 0);
  EXPECT_EQ(m.texture(KIT_UNIT_EMISSIVE).uv.slot, 1);
  const kit::Primitive& before = primitive_named(plain, "floor");
  ASSERT_EQ(p.vertices.size(), uv1.size() / 2);
  for (size_t i = 0; i < p.vertices.size(); ++i) {
    EXPECT_EQ(m.texture(KIT_UNIT_BASE_COLOR).uv.of(p.vertices[i]), before.vertices[i].texcoord) << "vertex " << i;
    EXPECT_EQ(m.texture(KIT_UNIT_EMISSIVE).uv.of(p.vertices[i]), glm::vec2(uv1[2 * i], uv1[2 * i + 1]))
        << "vertex " << i;
  }

  // A material whose only textures read TEXCOORD_1 puts it in slot 0.
  material["pbrMetallicRoughness"]["baseColorTexture"]["texCoord"] = 1;
  copy.save_json();
  const kit::Scene only_1 = kit::load_scene(copy.gltf.string());
  const kit::Primitive& q = primitive_named(only_1, "floor");
  const kit::Material& m1 = only_1.materials[static_cast<size_t>(q.material)];
  EXPECT_EQ(m1.uv_set_of_slot, (std::array<int, 2>{1, -1}));
  for (size_t i = 0; i < q.vertices.size(); ++i)
    EXPECT_EQ(q.vertices[i].texcoord, glm::vec2(uv1[2 * i], uv1[2 * i + 1])) << "vertex " << i;

  // A texture asking for a UV set the primitive lacks is refused by name.
  copy.doc["meshes"][floor.mesh]["primitives"][0]["attributes"].erase("TEXCOORD_1");
  copy.save_json();
  expect_error(copy.gltf, "its material's textures read TEXCOORD_1, which the primitive does not have");
}

// A vertex carries two UV slots: a material whose textures name three UV sets is
// refused, naming the texture and the sets.
TEST(SceneLoaderUv, AThirdUvSetInOneMaterialIsRefusedByName) {
  SceneCopy copy("default", "three_uv_sets");
  const FloorOfDefaultScene floor(copy.doc);
  json& material = copy.doc["materials"][floor.material];
  const json texture = material["pbrMetallicRoughness"]["baseColorTexture"]["index"];
  material["emissiveTexture"] = {{"index", texture}, {"texCoord", 2}};
  material["pbrMetallicRoughness"]["metallicRoughnessTexture"] = {{"index", texture}, {"texCoord", 1}};
  copy.save_json();
  expect_error(copy.gltf, "material '" + material.value("name", std::string()) +
                              "' emissiveTexture: texCoord 2 is a third UV set for one material (TEXCOORD_0 and TEXCOORD_1");
}

// Generated tangents follow the UVs the normal texture samples: its transform
// turning the UVs by 90 degrees turns the tangent with them.
TEST(SceneLoaderUv, GeneratedTangentsFollowTheNormalTexturesUv) {
  const glm::vec3 n(0, 0, 1);
  const std::vector<uint32_t> quad = {0, 1, 2, 0, 2, 3};
  std::vector<kit::Vertex> v = {vertex({0, 0, 0}, n, {0, 1}), vertex({1, 0, 0}, n, {1, 1}), vertex({1, 1, 0}, n, {1, 0}),
                                vertex({0, 1, 0}, n, {0, 0})};
  kit::TextureUv turned;
  turned.transform = glm::mat3(0, 1, 0, -1, 0, 0, 0, 0, 1);  // (u, v) -> (-v, u): rotation by 90 degrees
  kit::generate_tangents(v, quad);
  for (const kit::Vertex& vert : v) EXPECT_NEAR(vert.tangent.x, 1.0, kUnitTolerance) << "untransformed: T = +X";
  kit::generate_tangents(v, quad, turned);
  expect_valid_frame(v, "turned");
  // u' = -v grows where v shrinks, that is up the quad (+Y).
  for (const kit::Vertex& vert : v) EXPECT_NEAR(vert.tangent.y, 1.0, kUnitTolerance) << "turned: T = +Y";
}

}  // namespace
