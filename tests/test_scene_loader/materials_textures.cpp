// The glTF loader's materials and textures: alpha modes, images decoded and uploaded
// only as the material slots that sample them need (compressed when large), samplers,
// and each texture's own UV set and KHR_texture_transform.
#include <gtest/gtest.h>

#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

#include <array>
#include <cstddef>
#include <cstdint>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "base/error.h"
#include "gbuffer_layout.h"  // KIT_ALPHA_*, KIT_UNIT_*
#include "gl/gl_objects.h"
#include "gltf_expected.h"
#include "images/image_io.h"
#include "images/texture_compression.h"
#include "images/texture_decode.h"
#include "kit_test.h"
#include "kit_test_files.h"
#include "render/renderer.h"
#include "render/stages.h"
#include "scene/scene.h"
#include "scene_copy.h"
#include "tiny_scenes.h"

using nlohmann::json;
using namespace kit::test;  // the helpers of support/ included above

namespace {

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
  expect_scene_error(copy.gltf, "sampler 1 has wrapT 1234 (glTF allows");
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
  expect_scene_error(copy.gltf, "its material's textures read TEXCOORD_1, which the primitive does not have");
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
  expect_scene_error(copy.gltf, "material '" + material.value("name", std::string()) +
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
