#include <tiny_gltf.h>

#include <glm/gtc/constants.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>
#include <glm/gtc/type_ptr.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "scene/draco_mesh.h"
#include "base/error.h"
#include "gbuffer_layout.h"
#include "scene/gltf_accessors.h"
#include "scene/gltf_loader.h"

namespace kit::gltf {

namespace {

// Whether the file lists `name` among the extensions it uses (or requires).
bool uses_extension(const tinygltf::Model& model, const std::string& name) {
  for (const auto* list : {&model.extensionsUsed, &model.extensionsRequired})
    if (std::find(list->begin(), list->end(), name) != list->end()) return true;
  return false;
}

glm::mat4 node_local_matrix(const tinygltf::Node& node) {
  if (node.matrix.size() == 16) {
    glm::mat4 m;
    for (int i = 0; i < 16; ++i) glm::value_ptr(m)[i] = static_cast<float>(node.matrix[static_cast<size_t>(i)]);
    return m;
  }
  glm::mat4 m(1.0f);
  if (node.translation.size() == 3)
    m = glm::translate(m, glm::vec3(node.translation[0], node.translation[1], node.translation[2]));
  if (node.rotation.size() == 4) {
    glm::quat q(static_cast<float>(node.rotation[3]), static_cast<float>(node.rotation[0]),
                static_cast<float>(node.rotation[1]), static_cast<float>(node.rotation[2]));
    m *= glm::mat4_cast(q);
  }
  if (node.scale.size() == 3) m = glm::scale(m, glm::vec3(node.scale[0], node.scale[1], node.scale[2]));
  return m;
}

// A material's texture: its image and sampler (-1 each when the material has none;
// sampler -1 also when the texture names none); its UV is uv_mapping's.
MaterialTexture texture_source(const tinygltf::Model& model, int texture, const std::string& path) {
  if (texture < 0) return {};
  if (texture >= static_cast<int>(model.textures.size()))
    throw Error(path + ": texture index " + std::to_string(texture) + " does not exist");
  const tinygltf::Texture& t = model.textures[static_cast<size_t>(texture)];
  if (t.source < 0 || t.source >= static_cast<int>(model.images.size()))
    throw Error(path + ": texture " + std::to_string(texture) + " has no valid image source");
  if (t.sampler >= static_cast<int>(model.samplers.size()))
    throw Error(path + ": texture " + std::to_string(texture) + " names sampler " + std::to_string(t.sampler) +
                ", which does not exist");
  MaterialTexture out;
  out.image = t.source;
  out.sampler = std::max(t.sampler, -1);
  return out;
}

// A material's reference to one of its textures, as the file writes it.
struct TextureReference {
  const char* name = "";  // "baseColorTexture"
  int index = -1, texcoord = 0;
  const tinygltf::ExtensionMap* extensions = nullptr;
};
template <typename Info>  // tinygltf::TextureInfo or NormalTextureInfo
TextureReference texture_reference(const char* name, const Info& info) {
  return {name, info.index, info.texCoord, &info.extensions};
}
// The material's texture references, indexed like Material::textures.
std::array<TextureReference, kMaterialTextureCount> texture_references(const tinygltf::Material& m) {
  std::array<TextureReference, kMaterialTextureCount> refs;
  refs[KIT_UNIT_BASE_COLOR] = texture_reference("baseColorTexture", m.pbrMetallicRoughness.baseColorTexture);
  refs[KIT_UNIT_METALLIC_ROUGHNESS] =
      texture_reference("metallicRoughnessTexture", m.pbrMetallicRoughness.metallicRoughnessTexture);
  refs[KIT_UNIT_NORMAL_MAP] = texture_reference("normalTexture", m.normalTexture);
  refs[KIT_UNIT_EMISSIVE] = texture_reference("emissiveTexture", m.emissiveTexture);
  return refs;
}

// A glTF sampler with its values checked; an undefined filter is the default's.
TextureSampler texture_sampler(const tinygltf::Sampler& s, size_t index, const std::string& path) {
  auto check = [&](int value, const char* field, std::initializer_list<int> allowed, const char* names) {
    if (std::find(allowed.begin(), allowed.end(), value) == allowed.end())
      throw Error(path + ": sampler " + std::to_string(index) + " has " + field + " " + std::to_string(value) +
                  " (glTF allows " + names + ")");
    return static_cast<GLenum>(value);
  };
  constexpr const char* kWraps = "33071 CLAMP_TO_EDGE, 33648 MIRRORED_REPEAT, 10497 REPEAT";
  TextureSampler out;
  out.wrap_s = check(s.wrapS, "wrapS", {GL_CLAMP_TO_EDGE, GL_MIRRORED_REPEAT, GL_REPEAT}, kWraps);
  out.wrap_t = check(s.wrapT, "wrapT", {GL_CLAMP_TO_EDGE, GL_MIRRORED_REPEAT, GL_REPEAT}, kWraps);
  if (s.magFilter != -1) out.mag_filter = check(s.magFilter, "magFilter", {GL_NEAREST, GL_LINEAR}, "9728 NEAREST, 9729 LINEAR");
  if (s.minFilter != -1)
    out.min_filter = check(s.minFilter, "minFilter",
                           {GL_NEAREST, GL_LINEAR, GL_NEAREST_MIPMAP_NEAREST, GL_LINEAR_MIPMAP_NEAREST,
                            GL_NEAREST_MIPMAP_LINEAR, GL_LINEAR_MIPMAP_LINEAR},
                           "9728 NEAREST, 9729 LINEAR, 9984 to 9987 the mipmapped filters");
  return out;
}

class SceneBuilder {
 public:
  SceneBuilder(const tinygltf::Model& model, const std::string& path) : model_(model), path_(path), reader_{model, path, uses_extension(model, "KHR_mesh_quantization")} {}

  Scene build() {
    scene_.path = path_;
    for (size_t i = 0; i < model_.images.size(); ++i) {
      const tinygltf::Image& img = model_.images[i];
      if (img.image.empty() || img.width <= 0 || img.height <= 0) throw Error(path_ + ": image '" + img.uri + "' has no pixels");
      scene_.images.push_back({path_ + ": image " + std::to_string(i) + " ('" + img.uri + "')", img.width, img.height,
                               img.image, {}});
    }
    for (size_t i = 0; i < model_.samplers.size(); ++i) scene_.samplers.push_back(texture_sampler(model_.samplers[i], i, path_));
    for (const auto& m : model_.materials) scene_.materials.push_back(material(m));
    for (size_t mi = 0; mi < model_.meshes.size(); ++mi) {
      std::vector<int> prims;
      for (size_t pi = 0; pi < model_.meshes[mi].primitives.size(); ++pi) {
        int id = primitive(mi, pi);
        if (id >= 0) prims.push_back(id);
      }
      mesh_primitives_.push_back(prims);
    }
    int scene_index = model_.defaultScene >= 0 ? model_.defaultScene : 0;
    if (model_.scenes.empty()) throw Error(path_ + ": the file has no scene");
    if (scene_index >= static_cast<int>(model_.scenes.size())) throw Error(path_ + ": defaultScene does not exist");
    for (int root : model_.scenes[static_cast<size_t>(scene_index)].nodes) visit(root, glm::mat4(1.0f), 0);
    if (scene_.draws.empty()) throw Error(path_ + ": the scene draws no triangles");
    if (!scene_.cameras.empty()) scene_.camera = scene_.cameras.front();
    set_bounds_from_draws(scene_);
    return std::move(scene_);
  }

 private:
  Material material(const tinygltf::Material& m) {
    Material out;
    out.name = m.name;
    const auto& pbr = m.pbrMetallicRoughness;
    if (pbr.baseColorFactor.size() == 4)
      out.base_color_factor = glm::vec4(pbr.baseColorFactor[0], pbr.baseColorFactor[1], pbr.baseColorFactor[2], pbr.baseColorFactor[3]);
    out.metallic_factor = static_cast<float>(pbr.metallicFactor);
    out.roughness_factor = static_cast<float>(pbr.roughnessFactor);
    if (m.emissiveFactor.size() == 3) out.emissive = glm::vec3(m.emissiveFactor[0], m.emissiveFactor[1], m.emissiveFactor[2]);
    auto strength = m.extensions.find("KHR_materials_emissive_strength");
    if (strength != m.extensions.end() && strength->second.Has("emissiveStrength"))
      out.emissive *= static_cast<float>(strength->second.Get("emissiveStrength").GetNumberAsDouble());
    out.normal_scale = static_cast<float>(m.normalTexture.scale);
    out.alpha_mode = alpha_mode(m.alphaMode, m.name);
    out.alpha_cutoff = static_cast<float>(m.alphaCutoff);
    out.double_sided = m.doubleSided;
    const std::array<TextureReference, kMaterialTextureCount> refs = texture_references(m);
    for (int unit = 0; unit < kMaterialTextureCount; ++unit)
      out.texture(unit) = texture_source(model_, refs[static_cast<size_t>(unit)].index, path_);
    uv_mapping(m.name, refs, out);
    return out;
  }

  // Each texture's TextureUv and Material::uv_set_of_slot: the UV sets the
  // textures name go into the vertex's two UV slots, in the order of the textures'
  // units (base colour, metallic-roughness, normal, emissive); a third distinct set
  // is refused, as a vertex carries two.
  void uv_mapping(const std::string& name, const std::array<TextureReference, kMaterialTextureCount>& refs,
                  Material& out) {
    const std::string what = path_ + ": material '" + name + "'";
    out.uv_set_of_slot = {-1, -1};
    for (int unit = 0; unit < kMaterialTextureCount; ++unit) {
      const TextureReference& ref = refs[static_cast<size_t>(unit)];
      if (ref.index < 0) continue;
      TextureUv& uv = out.texture(unit).uv;
      int set = ref.texcoord;
      uv.transform = texture_transform(*ref.extensions, what + " " + ref.name, set);
      if (set < 0 || set > kMaxTexcoordSet)
        throw Error(what + " " + ref.name + ": texCoord " + std::to_string(set) + " is not a UV set the kit reads (0 to " +
                    std::to_string(kMaxTexcoordSet) + ")");
      if (out.uv_set_of_slot[0] < 0 || set == out.uv_set_of_slot[0]) {
        out.uv_set_of_slot[0] = set;
        uv.slot = 0;
      } else if (out.uv_set_of_slot[1] < 0 || set == out.uv_set_of_slot[1]) {
        out.uv_set_of_slot[1] = set;
        uv.slot = 1;
      } else {
        throw Error(what + " " + ref.name + ": texCoord " + std::to_string(set) + " is a third UV set for one material (TEXCOORD_" +
                    std::to_string(out.uv_set_of_slot[0]) + " and TEXCOORD_" + std::to_string(out.uv_set_of_slot[1]) +
                    " are read already); a vertex carries two");
      }
    }
    if (out.uv_set_of_slot[0] < 0) out.uv_set_of_slot[0] = 0;  // no texture: TEXCOORD_0, as a material without a file has
  }

  // KHR_texture_transform of a texture reference as its matrix
  // (texture_transform_matrix), and its texCoord override into `set`.
  static glm::mat3 texture_transform(const tinygltf::ExtensionMap& extensions, const std::string& what, int& set) {
    auto ext = extensions.find("KHR_texture_transform");
    if (ext == extensions.end()) return glm::mat3(1.0f);
    const tinygltf::Value& t = ext->second;
    auto number = [&](const tinygltf::Value& v, const std::string& field) {
      if (!v.IsNumber() || !std::isfinite(v.GetNumberAsDouble()))
        throw Error(what + ": KHR_texture_transform " + field + " is not a finite number");
      return static_cast<float>(v.GetNumberAsDouble());
    };
    auto pair = [&](const char* field, glm::vec2 fallback) {
      if (!t.Has(field)) return fallback;
      const tinygltf::Value& v = t.Get(field);
      if (!v.IsArray() || v.ArrayLen() != 2) throw Error(what + ": KHR_texture_transform " + field + " is not two numbers");
      return glm::vec2(number(v.Get(0), field), number(v.Get(1), field));
    };
    const glm::vec2 offset = pair("offset", glm::vec2(0.0f)), scale = pair("scale", glm::vec2(1.0f));
    const float rotation = t.Has("rotation") ? number(t.Get("rotation"), "rotation") : 0.0f;
    if (t.Has("texCoord")) {
      const double texcoord = t.Get("texCoord").IsNumber() ? t.Get("texCoord").GetNumberAsDouble() : -1.0;
      if (!(texcoord >= 0.0 && texcoord <= kMaxTexcoordSet && texcoord == std::floor(texcoord)))
        throw Error(what + ": KHR_texture_transform texCoord is not a UV set the kit reads (0 to " +
                    std::to_string(kMaxTexcoordSet) + ")");
      set = static_cast<int>(texcoord);
    }
    return texture_transform_matrix(offset, rotation, scale);
  }

  // glTF's alphaMode string; tinygltf fills in "OPAQUE" when it is absent.
  int alpha_mode(const std::string& mode, const std::string& material_name) {
    if (mode == "MASK") return KIT_ALPHA_MASK;
    if (mode == "BLEND") return KIT_ALPHA_BLEND;
    if (mode != "OPAQUE")
      scene_.warnings.push_back(path_ + ": material '" + material_name + "': alphaMode '" + mode +
                                "' is not glTF's (OPAQUE, MASK, BLEND); drawn as OPAQUE");
    return KIT_ALPHA_OPAQUE;
  }

  int primitive(size_t mesh, size_t prim) {
    const tinygltf::Primitive& p = model_.meshes[mesh].primitives[prim];
    std::string what = "mesh " + std::to_string(mesh) + " ('" + model_.meshes[mesh].name + "') primitive " + std::to_string(prim);
    const int mode = p.mode == -1 ? TINYGLTF_MODE_TRIANGLES : p.mode;
    if (mode != TINYGLTF_MODE_TRIANGLES && mode != TINYGLTF_MODE_TRIANGLE_STRIP && mode != TINYGLTF_MODE_TRIANGLE_FAN) {
      // Points and lines have no surface to put in a G-buffer: left out, said once.
      scene_.warnings.push_back(path_ + ": " + what + ": mode " + std::to_string(mode) +
                                " (points or lines) is not drawn; the kit draws triangles");
      return -1;
    }
    auto attr = [&](const std::string& name) {
      auto it = p.attributes.find(name);
      return it == p.attributes.end() ? -1 : it->second;
    };
    const std::optional<DracoPrimitive> draco = draco_primitive(p, mode, what);
    // An attribute's values: Draco's when its mesh holds the attribute, else its accessor's.
    auto read = [&](const std::string& name, int type, int components, AttributeFormats formats) {
      std::optional<DracoAttribute> decoded;
      if (draco) {
        auto id = draco->unique_ids.find(name);
        if (id != draco->unique_ids.end()) decoded = draco->mesh.attribute(id->second, path_ + ": " + what + " " + name);
      }
      return reader_.floats(attr(name), type, components, formats, what + " " + name, decoded ? &*decoded : nullptr);
    };
    if (attr("POSITION") < 0) throw Error(path_ + ": " + what + ": has no POSITION attribute");
    std::vector<float> pos = read("POSITION", TINYGLTF_TYPE_VEC3, 3, kPositionFormats);
    size_t n = pos.size() / 3;
    // No NORMAL: glTF asks for flat normals, computed below once the triangles are known.
    const bool flat = attr("NORMAL") < 0;
    std::vector<float> nrm = flat ? std::vector<float>(pos.size(), 0.0f) : read("NORMAL", TINYGLTF_TYPE_VEC3, 3, kDirectionFormats);
    if (nrm.size() / 3 != n) throw Error(path_ + ": " + what + ": NORMAL count differs from POSITION count");
    std::vector<float> tan;
    const Material* material =
        p.material >= 0 && p.material < static_cast<int>(scene_.materials.size()) ? &scene_.materials[static_cast<size_t>(p.material)] : nullptr;
    // The UV sets its material's textures read, one per vertex UV slot. A missing
    // TEXCOORD_0 reads as zero (a texture then shows one texel), another missing set is refused.
    const std::array<int, 2> uv_sets = material ? material->uv_set_of_slot : std::array<int, 2>{0, -1};
    std::array<std::vector<float>, 2> uv;
    for (size_t slot = 0; slot < 2; ++slot) {
      if (uv_sets[slot] < 0) continue;
      const std::string uv_name = "TEXCOORD_" + std::to_string(uv_sets[slot]);
      if (attr(uv_name) >= 0)
        uv[slot] = read(uv_name, TINYGLTF_TYPE_VEC2, 2, kTexcoordFormats);
      else if (uv_sets[slot] != 0)
        throw Error(path_ + ": " + what + ": its material's textures read " + uv_name + ", which the primitive does not have");
    }
    if (attr("TANGENT") >= 0) tan = read("TANGENT", TINYGLTF_TYPE_VEC4, 4, kDirectionFormats);
    // COLOR_0 multiplies the base colour; VEC3 means alpha 1.
    std::vector<float> color;
    size_t color_components = 0;
    if (attr("COLOR_0") >= 0) {
      const std::string color_what = what + " COLOR_0";
      const tinygltf::Accessor& acc = reader_.accessor(attr("COLOR_0"), color_what);
      if (acc.type != TINYGLTF_TYPE_VEC3 && acc.type != TINYGLTF_TYPE_VEC4)
        throw Error(path_ + ": " + color_what + ": accessor " + std::to_string(attr("COLOR_0")) + " is " +
                    accessor_type_name(acc.type) + "; COLOR_0 must be VEC3 or VEC4");
      color_components = acc.type == TINYGLTF_TYPE_VEC3 ? 3 : 4;
      color = read("COLOR_0", acc.type, static_cast<int>(color_components), kColorFormats);
    }
    if ((!uv[0].empty() && uv[0].size() / 2 != n) || (!uv[1].empty() && uv[1].size() / 2 != n) || (!tan.empty() && tan.size() / 4 != n) ||
        (!color.empty() && color.size() / color_components != n))
      throw Error(path_ + ": " + what + ": attribute counts differ from POSITION count");

    Primitive out;
    out.name = what;
    out.material = p.material;
    if (p.material >= static_cast<int>(model_.materials.size())) throw Error(path_ + ": " + what + ": material index does not exist");
    out.vertices.resize(n);
    bool clamped_color = false;
    for (size_t i = 0; i < n; ++i) {
      Vertex& v = out.vertices[i];
      v.position = glm::vec3(pos[3 * i], pos[3 * i + 1], pos[3 * i + 2]);
      v.normal = glm::vec3(nrm[3 * i], nrm[3 * i + 1], nrm[3 * i + 2]);
      if (!std::isfinite(v.position.x) || !std::isfinite(v.position.y) || !std::isfinite(v.position.z))
        throw Error(path_ + ": " + what + ": POSITION " + std::to_string(i) + " is not finite (NaN or Inf)");
      if (!std::isfinite(glm::dot(v.normal, v.normal)))
        throw Error(path_ + ": " + what + ": NORMAL " + std::to_string(i) + " is not finite (NaN or Inf)");
      v.texcoord = uv[0].empty() ? glm::vec2(0.0f) : glm::vec2(uv[0][2 * i], uv[0][2 * i + 1]);
      v.texcoord1 = uv[1].empty() ? glm::vec2(0.0f) : glm::vec2(uv[1][2 * i], uv[1][2 * i + 1]);
      v.tangent = tan.empty() ? glm::vec4(0.0f) : glm::vec4(tan[4 * i], tan[4 * i + 1], tan[4 * i + 2], tan[4 * i + 3]);
      for (size_t c = 0; c < color_components; ++c) {
        const float value = color[color_components * i + c];
        if (!std::isfinite(value))
          throw Error(path_ + ": " + what + ": COLOR_0 " + std::to_string(i) + " is not finite (NaN or Inf)");
        clamped_color |= value < 0.0f || value > 1.0f;
        v.color[static_cast<int>(c)] = vertex_color_component(value);
      }
    }
    if (clamped_color)
      scene_.warnings.push_back(path_ + ": " + what + ": COLOR_0 has FLOAT values outside [0, 1]; clamped to it");
    const int indices = index_accessor(p, what);
    if (draco) {
      const std::vector<uint32_t> corners = draco->mesh.triangle_indices();
      out.indices = indices >= 0 ? reader_.indices(indices, what + " indices", &corners) : corners;
    } else if (indices >= 0) {
      out.indices = reader_.indices(indices, what + " indices");
    } else {
      out.indices.resize(n);
      for (size_t i = 0; i < n; ++i) out.indices[i] = static_cast<uint32_t>(i);
    }
    for (size_t i = 0; i < out.indices.size(); ++i)
      if (out.indices[i] >= n)
        throw Error(path_ + ": " + what + ": index " + std::to_string(out.indices[i]) + " at position " + std::to_string(i) +
                    " is out of range (" + std::to_string(n) + " vertices)");
    if (mode != TINYGLTF_MODE_TRIANGLES) out.indices = triangle_list(out.indices, mode);
    if (out.indices.size() % 3 != 0) throw Error(path_ + ": " + what + ": index count is not a multiple of 3");
    set_bounds_from_vertices(out);
    if (flat) use_flat_normals(out);
    if (tan.empty()) {
      // Along the UVs the normal texture samples; without UVs, any frame around the normal.
      generate_tangents(out.vertices, out.indices, material ? material->texture(KIT_UNIT_NORMAL_MAP).uv : TextureUv{});
      out.tangents_generated = true;
    }
    scene_.primitives.push_back(std::move(out));
    return static_cast<int>(scene_.primitives.size()) - 1;
  }

  // KHR_draco_mesh_compression: the primitive's mesh decoded from the extension's
  // bufferView, and the Draco unique id of each attribute it holds, by glTF name.
  // Without Draco support the extension is passed over: a file requiring it was
  // refused (check_required_extensions), one only using it has accessors to read.
  struct DracoPrimitive {
    DracoMesh mesh;
    std::map<std::string, uint32_t> unique_ids;
  };
  std::optional<DracoPrimitive> draco_primitive(const tinygltf::Primitive& p, int mode, const std::string& what) const {
    auto ext = p.extensions.find("KHR_draco_mesh_compression");
    if (ext == p.extensions.end() || !draco_supported()) return std::nullopt;
    const std::string name = what + " KHR_draco_mesh_compression";
    if (mode != TINYGLTF_MODE_TRIANGLES)
      throw Error(path_ + ": " + name + ": the primitive's mode is " + std::to_string(mode) +
                  "; a Draco mesh is a triangle list (mode 4)");
    const size_t view_index = static_cast<size_t>(index_in(ext->second.Get("bufferView"), model_.bufferViews.size(), name + " bufferView"));
    const tinygltf::Value& attributes = ext->second.Get("attributes");
    if (!attributes.IsObject()) throw Error(path_ + ": " + name + ": attributes is not an object");
    std::map<std::string, uint32_t> unique_ids;
    for (const std::string& attribute : attributes.Keys())
      unique_ids[attribute] = static_cast<uint32_t>(index_in(attributes.Get(attribute), std::numeric_limits<int>::max(),
                                                             name + " attribute " + attribute + ": unique id"));
    const size_t length = model_.bufferViews[view_index].byteLength;
    if (length == 0) throw Error(path_ + ": " + name + ": bufferView " + std::to_string(view_index) + " is empty");
    size_t stride = 0;
    const unsigned char* bytes = reader_.view_bytes(static_cast<int>(view_index), 0, 1, length, false, name, "", &stride);
    return DracoPrimitive{DracoMesh(bytes, length, path_ + ": " + name), std::move(unique_ids)};
  }

  // The primitive's index accessor, -1 when it has none. A Draco primitive's waits
  // in its extension object while tinygltf parses (move_draco_indices).
  int index_accessor(const tinygltf::Primitive& p, const std::string& what) const {
    auto ext = p.extensions.find("KHR_draco_mesh_compression");
    if (ext == p.extensions.end() || !ext->second.Has(kDracoIndicesKey)) return p.indices;
    return index_in(ext->second.Get(kDracoIndicesKey), model_.accessors.size(), what + " indices accessor");
  }

  // A strip's or a fan's triangles as a list, each wound as glTF says (a strip's
  // odd triangles swap their first two corners to keep the winding).
  static std::vector<uint32_t> triangle_list(const std::vector<uint32_t>& in, int mode) {
    std::vector<uint32_t> out;
    for (size_t i = 2; i < in.size(); ++i) {
      if (mode == TINYGLTF_MODE_TRIANGLE_FAN) out.insert(out.end(), {in[0], in[i - 1], in[i]});
      else if (i % 2 == 0) out.insert(out.end(), {in[i - 2], in[i - 1], in[i]});
      else out.insert(out.end(), {in[i - 1], in[i - 2], in[i]});
    }
    return out;
  }

  // glTF's nodes form trees (a node has one parent at most), so each node is
  // visited once: a node reached twice is refused, which bounds the walk by the
  // node count (a graph listing each child twice would otherwise take 2^depth
  // visits) and catches cycles; the depth bound keeps the recursion off the stack's end.
  void visit(int node_index, const glm::mat4& parent, int depth) {
    if (node_index < 0 || node_index >= static_cast<int>(model_.nodes.size()))
      throw Error(path_ + ": node index " + std::to_string(node_index) + " does not exist");
    if (depth > kMaxNodeDepth)
      throw Error(path_ + ": the node hierarchy is deeper than " + std::to_string(kMaxNodeDepth) + " levels");
    if (visited_.empty()) visited_.assign(model_.nodes.size(), false);
    if (visited_[static_cast<size_t>(node_index)])
      throw Error(path_ + ": node " + std::to_string(node_index) +
                  " is reached twice (glTF nodes form a tree: one parent each, no cycles)");
    visited_[static_cast<size_t>(node_index)] = true;
    const tinygltf::Node& node = model_.nodes[static_cast<size_t>(node_index)];
    glm::mat4 world = parent * node_local_matrix(node);
    if (node.mesh >= 0) {
      if (node.mesh >= static_cast<int>(mesh_primitives_.size())) throw Error(path_ + ": node '" + node.name + "' names a mesh that does not exist");
      for (const glm::mat4& instance : instance_matrices(node, node_index))
        for (int prim : mesh_primitives_[static_cast<size_t>(node.mesh)]) {
          if (scene_.draws.size() >= kMaxSceneDraws)
            throw Error(path_ + ": node " + std::to_string(node_index) + " ('" + node.name + "'): the scene draws more than " +
                        std::to_string(kMaxSceneDraws) + " meshes (the kit's limit: each primitive of each node and "
                        "EXT_mesh_gpu_instancing instance is one draw)");
          scene_.draws.push_back({prim, world * instance});
        }
    }
    if (node.camera >= 0) camera(node, world);
    auto ext = node.extensions.find("KHR_lights_punctual");
    if (ext != node.extensions.end() && ext->second.Has("light")) light(index_in(ext->second.Get("light"), model_.lights.size(), "KHR_lights_punctual light index"), world);
    for (int child : node.children) visit(child, world, depth + 1);
  }

  void camera(const tinygltf::Node& node, const glm::mat4& world) {
    if (node.camera >= static_cast<int>(model_.cameras.size())) throw Error(path_ + ": node '" + node.name + "' names a camera that does not exist");
    const tinygltf::Camera& c = model_.cameras[static_cast<size_t>(node.camera)];
    const std::string what = path_ + ": camera " + std::to_string(node.camera) + " ('" + c.name + "')";
    auto positive = [](double v) { return v > 0.0 && std::isfinite(v); };
    Camera cam;
    cam.view = glm::inverse(world);
    cam.position = glm::vec3(world[3]);
    if (c.type == "perspective") {
      const tinygltf::PerspectiveCamera& p = c.perspective;
      if (!positive(p.yfov) || !(p.yfov < glm::pi<double>()))
        throw Error(what + " has yfov " + std::to_string(p.yfov) + " (must be between 0 and pi radians)");
      if (!positive(p.znear)) throw Error(what + " has znear " + std::to_string(p.znear) + " (must be > 0)");
      // Absent (0 in tinygltf): glTF's infinite projection; the kit's depth views need a finite far plane.
      if (p.zfar != 0.0 && !(positive(p.zfar) && p.zfar > p.znear))
        throw Error(what + " has zfar " + std::to_string(p.zfar) + " (must be greater than znear)");
      if (!(p.aspectRatio >= 0.0 && std::isfinite(p.aspectRatio)))
        throw Error(what + " has aspectRatio " + std::to_string(p.aspectRatio) + " (must be > 0, or left out)");
      cam.yfov = static_cast<float>(p.yfov);
      cam.znear = static_cast<float>(p.znear);
      cam.zfar = p.zfar > 0.0 ? static_cast<float>(p.zfar) : 1000.0f;
      cam.aspect_ratio = static_cast<float>(p.aspectRatio);
    } else if (c.type == "orthographic") {
      const tinygltf::OrthographicCamera& o = c.orthographic;
      if (o.xmag == 0.0 || o.ymag == 0.0 || !std::isfinite(o.xmag) || !std::isfinite(o.ymag))
        throw Error(what + " has xmag " + std::to_string(o.xmag) + " and ymag " + std::to_string(o.ymag) +
                    " (each must be a finite number other than 0)");
      if (!(o.znear >= 0.0 && positive(o.zfar) && o.zfar > o.znear))
        throw Error(what + " has znear " + std::to_string(o.znear) + " and zfar " + std::to_string(o.zfar) +
                    " (must be 0 <= znear < zfar)");
      cam.orthographic = true;
      cam.xmag = static_cast<float>(o.xmag);
      cam.ymag = static_cast<float>(o.ymag);
      cam.znear = static_cast<float>(o.znear);
      cam.zfar = static_cast<float>(o.zfar);
    } else {
      throw Error(what + " has type '" + c.type + "' (glTF cameras are perspective or orthographic)");
    }
    scene_.cameras.push_back(cam);
  }

  // An index an extension gives (a node's KHR_lights_punctual "light", ...): a whole
  // number below `count`. Read as a double and checked before it becomes an int:
  // tinygltf's GetNumberAsInt converts any double, which is undefined behaviour past
  // int's range (1e300). `what` names the index ("KHR_lights_punctual light index").
  int index_in(const tinygltf::Value& value, size_t count, const std::string& what) const {
    double index = value.IsNumber() ? value.GetNumberAsDouble() : -1.0;
    if (!(index >= 0.0 && index < static_cast<double>(count) && index == std::floor(index))) {
      std::ostringstream shown;
      if (value.IsNumber()) shown << index;
      else shown << "(not a number)";
      throw Error(path_ + ": " + what + " " + shown.str() + " does not exist");
    }
    return static_cast<int>(index);
  }

  // EXT_mesh_gpu_instancing: the node's mesh is drawn once per instance, at the
  // node's world matrix times the instance's T * R * S (each attribute optional).
  // A node without the extension has one instance, the identity.
  std::vector<glm::mat4> instance_matrices(const tinygltf::Node& node, int node_index) const {
    auto ext = node.extensions.find("EXT_mesh_gpu_instancing");
    if (ext == node.extensions.end()) return {glm::mat4(1.0f)};
    const std::string what = "node " + std::to_string(node_index) + " ('" + node.name + "') EXT_mesh_gpu_instancing";
    const tinygltf::Value& attributes = ext->second.Get("attributes");  // a null Value when absent
    struct Attribute {
      const char* name;
      int type, components;
      AttributeFormats formats;
      std::vector<float> values;
    };
    Attribute translation{"TRANSLATION", TINYGLTF_TYPE_VEC3, 3, kPositionFormats, {}};
    Attribute rotation{"ROTATION", TINYGLTF_TYPE_VEC4, 4, kRotationFormats, {}};
    Attribute scale{"SCALE", TINYGLTF_TYPE_VEC3, 3, kPositionFormats, {}};
    size_t count = 0;
    bool any = false;
    for (Attribute* a : {&translation, &rotation, &scale}) {
      if (!attributes.IsObject() || !attributes.Has(a->name)) continue;
      const std::string name = what + " " + a->name;
      const int accessor = index_in(attributes.Get(a->name), model_.accessors.size(), name + " accessor index");
      a->values = reader_.floats(accessor, a->type, a->components, a->formats, name);
      const size_t n = a->values.size() / static_cast<size_t>(a->components);
      if (any && n != count)
        throw Error(path_ + ": " + name + " has " + std::to_string(n) + " instances, the other attributes " +
                    std::to_string(count));
      count = n;
      any = true;
    }
    if (!any) throw Error(path_ + ": " + what + " has no TRANSLATION, ROTATION or SCALE attribute");
    if (count > kMaxSceneDraws)
      throw Error(path_ + ": " + what + " has " + std::to_string(count) + " instances, more than the kit draws (" +
                  std::to_string(kMaxSceneDraws) + " draws in all)");
    std::vector<glm::mat4> out(count, glm::mat4(1.0f));
    for (size_t i = 0; i < count; ++i) {
      glm::mat4& m = out[i];
      if (!translation.values.empty()) m = glm::translate(m, glm::make_vec3(&translation.values[3 * i]));
      if (!rotation.values.empty()) {
        const float* q = &rotation.values[4 * i];  // x, y, z, w
        // Normalized integer quaternions are unit only to their precision.
        const glm::quat unit = glm::normalize(glm::quat(q[3], q[0], q[1], q[2]));
        if (!std::isfinite(unit.w)) throw Error(path_ + ": " + what + " ROTATION " + std::to_string(i) + " is not a rotation");
        m *= glm::mat4_cast(unit);
      }
      if (!scale.values.empty()) m = glm::scale(m, glm::make_vec3(&scale.values[3 * i]));
    }
    return out;
  }

  void light(int index, const glm::mat4& world) {
    if (index < 0 || index >= static_cast<int>(model_.lights.size()))
      throw Error(path_ + ": KHR_lights_punctual light index " + std::to_string(index) + " does not exist");
    const tinygltf::Light& l = model_.lights[static_cast<size_t>(index)];
    const std::string what = path_ + ": KHR_lights_punctual light " + std::to_string(index);
    Light out;
    if (l.type == "point") out.type = KIT_LIGHT_POINT;
    else if (l.type == "spot") out.type = KIT_LIGHT_SPOT;
    else if (l.type == "directional") out.type = KIT_LIGHT_DIRECTIONAL;
    else throw Error(what + " has type '" + l.type + "' (must be point, spot or directional)");
    out.position = glm::vec3(world[3]);
    // Spot and directional lights shine along their node's -Z; a node scaled to
    // nothing gives no direction.
    out.direction = glm::normalize(glm::vec3(world * glm::vec4(0, 0, -1, 0)));
    if (out.type != KIT_LIGHT_POINT && !std::isfinite(out.direction.x + out.direction.y + out.direction.z))
      throw Error(what + " (" + l.type + ") is on a node whose transform has no -Z direction (a zero scale)");
    if (l.color.size() == 3) out.color = glm::vec3(l.color[0], l.color[1], l.color[2]);
    out.intensity = static_cast<float>(l.intensity);
    if (!std::isfinite(out.intensity) || out.intensity < 0.0f)
      throw Error(what + " has intensity " + std::to_string(l.intensity) + " (must be a finite value >= 0)");
    // glTF: range, when present, is > 0; tinygltf reads an absent one as 0 (unlimited).
    if (!(l.range >= 0.0) || !std::isfinite(l.range))
      throw Error(what + " has range " + std::to_string(l.range) +
                  " (must be a positive distance, or left out for unlimited)");
    // The spec: range does not apply to a directional light (it reaches everywhere).
    out.range = out.type == KIT_LIGHT_DIRECTIONAL ? 0.0f : static_cast<float>(l.range);
    out.inner_cone = static_cast<float>(l.spot.innerConeAngle);
    out.outer_cone = static_cast<float>(l.spot.outerConeAngle);
    scene_.lights.push_back(out);
  }

  const tinygltf::Model& model_;
  const std::string& path_;
  AccessorReader reader_;
  Scene scene_;
  std::vector<std::vector<int>> mesh_primitives_;
  std::vector<bool> visited_;
};

}  // namespace

Scene build_scene(const tinygltf::Model& model, const std::string& path) { return SceneBuilder(model, path).build(); }

}  // namespace kit::gltf
