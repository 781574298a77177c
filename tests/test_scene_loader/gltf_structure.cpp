// The glTF loader (common/scene/gltf_loader.cpp, gltf_builder.cpp) on broken and hostile
// files: each fails with a kit::Error naming the file and the problem, never a crash, a
// hang or a read outside the scene; and the glTF core features beyond the kit's own
// scenes (required extensions, points and lines, no normals, strips and fans).
#include <gtest/gtest.h>

#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

#include <sys/stat.h>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <string>
#include <vector>

#include "gltf_expected.h"
#include "kit_test.h"
#include "kit_test_files.h"
#include "render/stages.h"
#include "scene/scene.h"
#include "scene_copy.h"

namespace fs = std::filesystem;
using nlohmann::json;
using namespace kit::test;  // the helpers of support/ included above

namespace {

TEST(SceneLoaderErrors, MissingFile) {
  fs::path missing = kit::test::temp_dir("scene_loader/missing") / "no_such_scene.gltf";
  expect_scene_error(missing, "scene file not found");
}

TEST(SceneLoaderErrors, TruncatedJson) {
  SceneCopy copy("sphere", "truncated");
  std::string text = kit::test::read_file(copy.gltf);
  kit::test::write_file(copy.gltf, text.substr(0, text.size() / 2));
  expect_scene_error(copy.gltf, "invalid glTF");
  expect_scene_error(copy.gltf, "parse error");
}

TEST(SceneLoaderErrors, MissingBuffer) {
  SceneCopy copy("sphere", "missing_bin");
  fs::remove(copy.bin);
  expect_scene_error(copy.gltf, "invalid glTF");
  expect_scene_error(copy.gltf, copy.bin.filename().string());  // says which file is missing
}

TEST(SceneLoaderErrors, OutOfRangeIndex) {
  SceneCopy copy("sphere", "bad_index");
  constexpr uint32_t kBadIndex = 0x00ffffffu;
  constexpr size_t kPatchedPosition = 7;  // any index inside the list
  copy.patch_bin(copy.byte_offset(copy.accessor("indices"), kPatchedPosition, 1, 0), kBadIndex);
  expect_scene_error(copy.gltf, "index " + std::to_string(kBadIndex) + " at position " + std::to_string(kPatchedPosition) +
                              " is out of range");
}

TEST(SceneLoaderErrors, WrongAccessorType) {
  SceneCopy copy("sphere", "vec2_position");
  copy.doc["accessors"][static_cast<size_t>(copy.accessor("POSITION"))]["type"] = "VEC2";
  copy.save_json();
  expect_scene_error(copy.gltf, "POSITION: accessor " + std::to_string(copy.accessor("POSITION")) + " has the wrong type");
}

TEST(SceneLoaderErrors, NanPosition) {
  SceneCopy copy("sphere", "nan_position");
  constexpr size_t kVertex = 40;
  copy.patch_bin(copy.byte_offset(copy.accessor("POSITION"), kVertex, 3, 1), std::numeric_limits<float>::quiet_NaN());
  expect_scene_error(copy.gltf, "POSITION " + std::to_string(kVertex) + " is not finite");
}

TEST(SceneLoaderErrors, AccessorPastTheEndOfItsBuffer) {
  SceneCopy copy("sphere", "short_view");
  size_t position = static_cast<size_t>(copy.accessor("POSITION"));
  copy.doc["accessors"][position]["count"] = copy.doc["accessors"][position]["count"].get<size_t>() * 4;
  copy.save_json();
  expect_scene_error(copy.gltf, "reads past the end of its buffer");
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
  expect_scene_error(copy.gltf, "reads past the end of its buffer");
}

TEST(SceneLoaderHostile, ByteOffsetNearTwoToThe64IsRefused) {
  SceneCopy copy("sphere", "huge_offset");
  size_t position = static_cast<size_t>(copy.accessor("POSITION"));
  const size_t offset = ~size_t{0} - 7;  // view offset + this wraps to just before the buffer
  const size_t count = copy.doc["accessors"][position]["count"];
  EXPECT_LT(naive_accessor_end(offset, 12, count, 12), offset) << "witness: the old sum wraps";
  copy.doc["accessors"][position]["byteOffset"] = offset;
  copy.save_json();
  expect_scene_error(copy.gltf, "byteOffset");
}

TEST(SceneLoaderHostile, DeeplyNestedJsonIsRefusedBeforeParsing) {
  SceneCopy copy("sphere", "deep_json");
  std::string text = kit::test::read_file(copy.gltf);
  const size_t depth = 100000;  // tinygltf's recursive parser runs off the stack at this depth
  std::string deep = "\"extras\": " + std::string(depth, '[') + std::string(depth, ']') + ",";
  text.insert(text.find('{') + 1, deep);
  kit::test::write_file(copy.gltf, text);
  expect_scene_error(copy.gltf, "nested deeper than 64");
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
  expect_scene_error(copy.gltf, "reached twice");
}

TEST(SceneLoaderHostile, UrisOutsideTheSceneFolderAreRefused) {
  SceneCopy copy("sphere", "escape/inner");
  fs::path outside = copy.dir.parent_path() / "outside.bin";
  fs::copy_file(copy.bin, outside, fs::copy_options::overwrite_existing);
  copy.doc["buffers"][0]["uri"] = "../outside.bin";
  copy.save_json();
  expect_scene_error(copy.gltf, "outside the scene's folder");
  copy.doc["buffers"][0]["uri"] = fs::absolute(outside).string();
  copy.save_json();
  expect_scene_error(copy.gltf, "outside the scene's folder");
  // A link inside the folder that points out of it is refused too.
  fs::create_symlink(outside, copy.dir / "link.bin");
  copy.doc["buffers"][0]["uri"] = "link.bin";
  copy.save_json();
  expect_scene_error(copy.gltf, "symbolic link");
}

// ---- glTF core features beyond the kit's own scenes ----

TEST(SceneLoaderGltf, RequiredExtensionTheKitLacksIsRefusedByName) {
  SceneCopy copy("sphere", "required_extension");
  copy.doc["extensionsUsed"] = {"EXT_meshopt_compression"};
  copy.save_json();
  EXPECT_NO_THROW(kit::load_scene(copy.gltf.string())) << "witness: merely used, it loads";
  copy.doc["extensionsRequired"] = {"EXT_meshopt_compression"};
  copy.save_json();
  expect_scene_error(copy.gltf, "requires the glTF extension EXT_meshopt_compression");
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

}  // namespace
