// Draco-compressed glTF (KHR_draco_mesh_compression), decoded by libdraco in the
// loader (common/scene/draco_mesh.*): a compressed copy of a kit scene, written by
// libdraco's encoder (tests/support/draco_scenes.h), loads to the vertices and
// indices of the original, within the quantization step where positions are
// quantized (computed in double); a corrupt Draco buffer and accessors that
// disagree with the decoded mesh are refused naming the file and the primitive.
#include <gtest/gtest.h>

#include <draco/compression/decode.h>
#include <nlohmann/json.hpp>
#include <tiny_gltf.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>
#include <string>
#include <vector>

#include "scene/draco_mesh.h"
#include "draco_scenes.h"
#include "base/error.h"
#include "images/image_io.h"
#include "kit_test.h"
#include "kit_test_files.h"
#include "scene/scene.h"
#include "render/stages.h"

namespace fs = std::filesystem;
using nlohmann::json;
using kit::test::expect_scene_error;

namespace {

// The default scene: meshes with and without TANGENT, shared geometry, textures.
const char* const kScene = "default";

std::string shell_quoted(const fs::path& p) { return "'" + p.string() + "'"; }

// A Draco copy of kScene in this test's own folder, its JSON at hand to be broken.
struct DracoCopy {
  fs::path gltf, bin;
  json doc;

  DracoCopy(const std::string& case_name, int position_bits) {
    gltf = kit::test::write_draco_copy(kScene, kit::test::temp_dir("draco/" + case_name), position_bits);
    bin = gltf.parent_path() / (gltf.stem().string() + ".bin");
    doc = json::parse(kit::test::read_file(gltf));
  }
  void save_json() const { kit::test::write_file(gltf, doc.dump(2)); }
  const json& first_primitive() const { return doc["meshes"][0]["primitives"][0]; }
  json& draco_view() { return doc["bufferViews"][first_primitive()["extensions"]["KHR_draco_mesh_compression"]["bufferView"].get<size_t>()]; }
  // The bytes of the first primitive's Draco bufferView, as they are in the .bin now.
  std::string draco_bytes() {
    const json& view = draco_view();
    return kit::test::read_file(bin).substr(view["byteOffset"].get<size_t>(), view["byteLength"].get<size_t>());
  }
};

// What libdraco itself says of `bytes`: whether they decode to a mesh.
bool draco_decodes(const std::string& bytes) {
  draco::DecoderBuffer buffer;
  buffer.Init(bytes.data(), bytes.size());
  draco::Decoder decoder;
  return decoder.DecodeMeshFromBuffer(&buffer).ok();
}

// The copy as one .glb: its JSON, then its .bin as the BIN chunk (buffer 0 loses its
// uri); images stay files beside it. glTF 2.0 "GLB File Format Specification".
fs::path write_glb(const DracoCopy& copy) {
  json doc = copy.doc;
  doc["buffers"][0].erase("uri");
  std::string text = doc.dump(), bin = kit::test::read_file(copy.bin);
  text.resize((text.size() + 3) / 4 * 4, ' ');
  bin.resize((bin.size() + 3) / 4 * 4, '\0');
  auto word = [](uint32_t v) { return std::string(reinterpret_cast<const char*>(&v), 4); };
  const std::string glb = "glTF" + word(2) + word(static_cast<uint32_t>(12 + 8 + text.size() + 8 + bin.size())) +
                          word(static_cast<uint32_t>(text.size())) + "JSON" + text +
                          word(static_cast<uint32_t>(bin.size())) + std::string("BIN\0", 4) + bin;
  const fs::path path = copy.gltf.parent_path() / (copy.gltf.stem().string() + ".glb");
  kit::test::write_file(path, glb);
  return path;
}

bool same_bits(float a, float b) { return std::memcmp(&a, &b, sizeof a) == 0; }

// Every vertex attribute bit for bit and every index, primitive by primitive.
void expect_identical_primitives(const kit::Scene& expected, const kit::Scene& actual) {
  ASSERT_EQ(actual.primitives.size(), expected.primitives.size());
  for (size_t p = 0; p < expected.primitives.size(); ++p) {
    const kit::Primitive& e = expected.primitives[p];
    const kit::Primitive& a = actual.primitives[p];
    ASSERT_EQ(a.vertices.size(), e.vertices.size()) << e.name;
    EXPECT_EQ(a.indices, e.indices) << e.name;
    EXPECT_EQ(a.tangents_generated, e.tangents_generated) << e.name;
    size_t differing = 0;
    for (size_t i = 0; i < e.vertices.size(); ++i) {
      const kit::Vertex &ev = e.vertices[i], &av = a.vertices[i];
      for (int c = 0; c < 3; ++c)
        differing += !same_bits(av.position[c], ev.position[c]) + !same_bits(av.normal[c], ev.normal[c]);
      for (int c = 0; c < 2; ++c) differing += !same_bits(av.texcoord[c], ev.texcoord[c]);
      for (int c = 0; c < 4; ++c) differing += !same_bits(av.tangent[c], ev.tangent[c]);
    }
    EXPECT_EQ(differing, 0u) << e.name << ": vertex components that differ";
  }
}

// Debian 12's tinygltf (2.7) refuses a Draco copy (a
// primitive's index accessor without a bufferView); Debian 13's 2.9 loads it, with no
// bufferView behind any of the primitives' accessors. Either way tinygltf alone gets none
// of the vertices: what the kit loads came through the decoder, which must keep the
// indices out of tinygltf's sight where it refuses them.
void expect_tinygltf_alone_gets_none(bool loaded, const tinygltf::Model& model, const std::string& err) {
  if (!loaded) {
    EXPECT_NE(err.find("invalid bufferView"), std::string::npos) << err;
    return;
  }
  for (const tinygltf::Mesh& mesh : model.meshes)
    for (const tinygltf::Primitive& prim : mesh.primitives)
      for (const auto& [name, index] : prim.attributes)
        EXPECT_EQ(model.accessors.at(static_cast<size_t>(index)).bufferView, -1) << name;
}

TEST(Draco, UnquantizedCopyLoadsToExactlyTheSameVerticesAndIndices) {
  const DracoCopy copy("lossless", 0);
  // Witness: the copy's vertex data is only in Draco meshes (no accessor of a
  // primitive has a bufferView left), so what loads came through the decoder.
  for (const json& mesh : copy.doc["meshes"])
    for (const json& prim : mesh["primitives"]) {
      ASSERT_TRUE(prim["extensions"].contains("KHR_draco_mesh_compression"));
      for (const auto& [name, index] : prim["attributes"].items())
        ASSERT_FALSE(copy.doc["accessors"][index.get<size_t>()].contains("bufferView")) << name;
    }
  // Witness: tinygltf alone gets none of the vertices (expect_tinygltf_alone_gets_none).
  tinygltf::Model model;
  tinygltf::TinyGLTF parser;
  std::string err, warn;
  expect_tinygltf_alone_gets_none(parser.LoadASCIIFromFile(&model, &err, &warn, copy.gltf.string()), model, err);

  const kit::Scene original = kit::load_scene(kit::resolve_scene(kScene));
  const kit::Scene decoded = kit::load_scene(copy.gltf.string());
  expect_identical_primitives(original, decoded);
  EXPECT_EQ(decoded.draws.size(), original.draws.size());
}

TEST(Draco, GlbCopyLoadsAsTheGltfCopy) {
  const DracoCopy copy("glb", 0);
  const fs::path glb = write_glb(copy);
  tinygltf::Model model;
  tinygltf::TinyGLTF parser;
  std::string err, warn;
  expect_tinygltf_alone_gets_none(parser.LoadBinaryFromFile(&model, &err, &warn, glb.string()), model, err);
  expect_identical_primitives(kit::load_scene(copy.gltf.string()), kit::load_scene(glb.string()));
}

TEST(Draco, DracoDataIsReadBeforeTheFallbackAccessors) {
  // A file that only uses Draco keeps uncompressed accessors for decoders without it.
  // Here their POSITION data is NaN: read, it would be refused.
  DracoCopy copy("fallback", 0);
  const json original = json::parse(kit::test::read_file(kit::resolve_scene(kScene)));
  for (size_t i = 0; i < original["accessors"].size(); ++i)
    for (const char* key : {"bufferView", "byteOffset"})
      if (original["accessors"][i].contains(key)) copy.doc["accessors"][i][key] = original["accessors"][i][key];
  copy.doc.erase("extensionsRequired");
  const json& position = original["accessors"][copy.first_primitive()["attributes"]["POSITION"].get<size_t>()];
  const json& view = original["bufferViews"][position["bufferView"].get<size_t>()];
  std::string bin = kit::test::read_file(copy.bin);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (size_t i = 0; i < position["count"].get<size_t>() * 3; ++i)
    std::memcpy(&bin[view.value("byteOffset", size_t{0}) + position.value("byteOffset", size_t{0}) + 4 * i], &nan, 4);
  kit::test::write_file(copy.bin, bin);

  json without_draco = copy.doc;
  for (json& mesh : without_draco["meshes"])
    for (json& prim : mesh["primitives"]) prim.erase("extensions");
  const fs::path fallback_only = copy.gltf.parent_path() / "fallback_only.gltf";
  kit::test::write_file(fallback_only, without_draco.dump(2));
  expect_scene_error(fallback_only, "POSITION 0 is not finite");  // witness: the fallback data is bad

  copy.save_json();
  expect_identical_primitives(kit::load_scene(kit::resolve_scene(kScene)), kit::load_scene(copy.gltf.string()));
}

TEST(Draco, QuantizedPositionsLieWithinHalfAQuantizationStep) {
  constexpr int kBits = 12;
  const DracoCopy copy("quantized", kBits);
  const kit::Scene original = kit::load_scene(kit::resolve_scene(kScene));
  const kit::Scene decoded = kit::load_scene(copy.gltf.string());
  ASSERT_EQ(decoded.primitives.size(), original.primitives.size());
  size_t moved = 0;
  for (size_t p = 0; p < original.primitives.size(); ++p) {
    const kit::Primitive& e = original.primitives[p];
    const kit::Primitive& a = decoded.primitives[p];
    ASSERT_EQ(a.vertices.size(), e.vertices.size()) << e.name;
    EXPECT_EQ(a.indices, e.indices) << e.name;
    // Draco quantizes POSITION over its bounding box's largest side, in 2^bits - 1
    // steps: rounding moves a coordinate by at most half a step, and dequantizing
    // in float adds a few ulps of the coordinates' magnitude.
    glm::dvec3 lo(e.vertices[0].position), hi = lo;
    for (const kit::Vertex& v : e.vertices) {
      lo = glm::min(lo, glm::dvec3(v.position));
      hi = glm::max(hi, glm::dvec3(v.position));
    }
    const glm::dvec3 extent = hi - lo;
    const double range = std::max({extent.x, extent.y, extent.z});
    const double magnitude = std::max(glm::length(lo), glm::length(hi)) + range;
    const double bound = 0.5 * range / ((1 << kBits) - 1) + 4.0 * std::numeric_limits<float>::epsilon() * magnitude;
    double worst = 0.0;
    for (size_t i = 0; i < e.vertices.size(); ++i) {
      const glm::dvec3 error = glm::abs(glm::dvec3(a.vertices[i].position) - glm::dvec3(e.vertices[i].position));
      worst = std::max({worst, error.x, error.y, error.z});
      moved += error != glm::dvec3(0.0);
      // Normals and UVs are not quantized; tangents are, where the loader made them from positions.
      EXPECT_EQ(a.vertices[i].normal, e.vertices[i].normal) << e.name << " vertex " << i;
      EXPECT_EQ(a.vertices[i].texcoord, e.vertices[i].texcoord) << e.name << " vertex " << i;
      if (!e.tangents_generated) {
        EXPECT_EQ(a.vertices[i].tangent, e.vertices[i].tangent) << e.name << " vertex " << i;
      }
    }
    EXPECT_LE(worst, bound) << e.name << ": a position moved more than half a quantization step";
  }
  EXPECT_GT(moved, 0u) << "witness: quantization moved no position, so the bound was never tested";
}

TEST(Draco, CorruptCompressedBufferIsRefusedNamingFileAndPrimitive) {
  const std::string primitive = "mesh 0 ('" + DracoCopy("names", 0).doc["meshes"][0].value("name", "") + "') primitive 0";
  {
    DracoCopy copy("flipped", 0);
    // Draco's header starts with the bytes "DRACO": flipped, no decoder takes them.
    const size_t start = copy.draco_view()["byteOffset"].get<size_t>();
    std::string bin = kit::test::read_file(copy.bin);
    ASSERT_EQ(bin.compare(start, 5, "DRACO"), 0);
    for (size_t i = start; i < start + 5; ++i) bin[i] = static_cast<char>(~bin[i]);
    kit::test::write_file(copy.bin, bin);
    ASSERT_FALSE(draco_decodes(copy.draco_bytes())) << "witness: libdraco decodes the flipped bytes";
    expect_scene_error(copy.gltf, primitive + " KHR_draco_mesh_compression: Draco cannot decode its mesh: ");
  }
  {
    DracoCopy copy("truncated", 0);
    ASSERT_TRUE(draco_decodes(copy.draco_bytes())) << "the untouched copy should decode";
    json& view = copy.draco_view();
    view["byteLength"] = view["byteLength"].get<size_t>() / 2;
    copy.save_json();
    ASSERT_FALSE(draco_decodes(copy.draco_bytes())) << "witness: libdraco decodes the first half";
    expect_scene_error(copy.gltf, primitive + " KHR_draco_mesh_compression: Draco cannot decode its mesh: ");
  }
}

TEST(Draco, AccessorsThatDisagreeWithTheDecodedMeshAreRefused) {
  const DracoCopy intact("agreeing", 0);
  ASSERT_NO_THROW(kit::load_scene(intact.gltf.string())) << "witness: the unaltered copy loads";
  const json& prim = intact.first_primitive();
  const size_t position = prim["attributes"]["POSITION"].get<size_t>();
  const size_t points = intact.doc["accessors"][position]["count"].get<size_t>();
  {
    DracoCopy copy("position_count", 0);
    copy.doc["accessors"][position]["count"] = points - 1;
    copy.save_json();
    expect_scene_error(copy.gltf, "POSITION: accessor " + std::to_string(position) + " has count " + std::to_string(points - 1) +
                                ", but the Draco mesh decoded " + std::to_string(points) + " points");
  }
  {
    DracoCopy copy("index_count", 0);
    const size_t indices = prim["indices"].get<size_t>();
    const size_t count = copy.doc["accessors"][indices]["count"].get<size_t>();
    copy.doc["accessors"][indices]["count"] = count + 3;
    copy.save_json();
    expect_scene_error(copy.gltf, "indices: index accessor " + std::to_string(indices) + " has count " +
                                std::to_string(count + 3) + ", but the Draco mesh decoded " + std::to_string(count / 3) +
                                " triangles");
  }
  {
    // Normalized UNSIGNED_SHORT is a valid TEXCOORD type, but not what Draco decoded.
    DracoCopy copy("texcoord_type", 0);
    const size_t texcoord = prim["attributes"]["TEXCOORD_0"].get<size_t>();
    copy.doc["accessors"][texcoord]["componentType"] = 5123;
    copy.doc["accessors"][texcoord]["normalized"] = true;
    copy.save_json();
    expect_scene_error(copy.gltf, "TEXCOORD_0: accessor " + std::to_string(texcoord) +
                                " has component type normalized UNSIGNED_SHORT, but Draco decoded FLOAT");
  }
  {
    DracoCopy copy("unique_id", 0);
    copy.doc["meshes"][0]["primitives"][0]["extensions"]["KHR_draco_mesh_compression"]["attributes"]["NORMAL"] = 99;
    copy.save_json();
    expect_scene_error(copy.gltf, "NORMAL: the Draco mesh has no attribute with unique id 99");
  }
}

TEST(Draco, KitRenderDrawsTheCompressedSceneAsTheUncompressedOne) {
  // Stage 1's G-buffer (solution of lab 1: a student copy for lab 2 on holds it):
  // positions, normals and the albedo that the UVs sample, as floats.
  const fs::path dir = kit::test::temp_dir("draco/kit_render");
  const char* const views[] = {"position", "normal", "albedo"};
  auto render = [&](const fs::path& scene, const std::string& name) {
    std::string command = shell_quoted(kit::test::tool("kit-render")) + " --solution --stage gbuffer --size 160x120 --scene " +
                          shell_quoted(scene);
    for (const char* view : views) command += std::string(" --view ") + view + " --out " + shell_quoted(dir / (name + "-" + view + ".exr"));
    std::string output;
    EXPECT_EQ(kit::test::run(command, &output), 0) << output;
    std::vector<kit::Image> images;
    for (const char* view : views) images.push_back(kit::read_image((dir / (name + "-" + view + ".exr")).string()));
    return images;
  };
  const std::vector<kit::Image> original = render(kit::resolve_scene(kScene), "original");
  const std::vector<kit::Image> decoded = render(kit::test::write_draco_copy(kScene, dir / "lossless", 0), "draco");
  // Witness: the comparison sees geometry: positions quantized to 6 bits change the image.
  const std::vector<kit::Image> coarse = render(kit::test::write_draco_copy(kScene, dir / "coarse", 6), "coarse");
  for (size_t v = 0; v < original.size(); ++v) {
    EXPECT_EQ(kit::test::max_abs_difference(original[v], decoded[v]), 0.0f) << views[v];
    EXPECT_GT(kit::test::max_abs_difference(original[v], coarse[v]), 0.01f) << views[v] << " (witness)";
  }
}

}  // namespace
