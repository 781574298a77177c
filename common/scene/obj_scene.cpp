#include "scene/obj_scene.h"

#include "base/error.h"
#include "gbuffer_layout.h"
#include "images/image_codecs.h"

#if KIT_HAS_OBJ
#include <tiny_obj_loader.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <istream>
#include <limits>
#include <map>
#include <unordered_map>

#include "base/safe_file.h"
#include "images/texture_decode.h"
#endif

namespace kit {

bool is_obj_path(const std::string& path) { return has_extension(path, ".obj"); }

#if !KIT_HAS_OBJ

bool obj_scenes_supported() { return false; }

Scene load_obj_scene(const std::string& path) {
  throw Error(path + ": this build has no OBJ support: install libtinyobjloader-dev and rebuild");
}

#else

bool obj_scenes_supported() { return true; }

namespace {

namespace fs = std::filesystem;

constexpr std::uintmax_t kMaxObjFileBytes = std::uintmax_t(1) << 30;  // an .obj, .mtl or texture: glTF's limit
constexpr const char* kOutsideFolder = "lies outside the scene's folder (a scene may only name files beside it or below it)";

// The material the kit gives faces without one (no usemtl, or a name no MTL defines):
// a light grey dielectric, as most OBJ viewers show such faces.
Material default_obj_material() {
  Material m;
  m.name = "(no material)";
  m.base_color_factor = glm::vec4(0.8f, 0.8f, 0.8f, 1.0f);
  m.metallic_factor = 0.0f;
  m.roughness_factor = 0.5f;
  return m;
}

// The OBJ or MTL bytes, read once under safe_file's rules, as the istream tinyobjloader
// reads (no second copy of a file that may be large).
class BytesStreamBuf : public std::streambuf {
 public:
  explicit BytesStreamBuf(const std::vector<unsigned char>& bytes) {
    char* begin = reinterpret_cast<char*>(const_cast<unsigned char*>(bytes.data()));
    setg(begin, begin, begin + bytes.size());
  }
};

// Where a material was defined, and which of the MTL PBR extension's scalars it gives
// (tinyobjloader reads an absent Pr or Pm as 0, the same as an explicit 0).
struct MtlDefinition {
  std::string file;  // the MTL as the OBJ names it
  size_t line = 0;   // of its newmtl; 0: unknown
  bool has_roughness = false, has_metallic = false;
};

// The definitions of an MTL file in the order tinyobjloader's LoadMtl appends its
// materials: it starts with an unnamed material, pushes the current one at each
// newmtl when it has a name, and always pushes the last.
std::vector<MtlDefinition> scan_mtl(const std::vector<unsigned char>& bytes, const std::string& file) {
  struct Entry {
    std::string name;
    MtlDefinition definition;
  };
  std::vector<Entry> entries{{"", {file, 0, false, false}}};
  size_t line_number = 0;
  for (size_t start = 0; start < bytes.size();) {
    size_t end = start;
    while (end < bytes.size() && bytes[end] != '\n') ++end;
    std::string line(bytes.begin() + static_cast<std::ptrdiff_t>(start), bytes.begin() + static_cast<std::ptrdiff_t>(end));
    start = end + 1;
    ++line_number;
    while (!line.empty() && (line.back() == '\r' || line.back() == ' ' || line.back() == '\t')) line.pop_back();
    size_t first = line.find_first_not_of(" \t");
    if (first == std::string::npos) continue;
    const std::string text = line.substr(first);
    auto keyword = [&](const char* word) {
      const size_t n = std::char_traits<char>::length(word);
      return text.size() > n && text.compare(0, n, word) == 0 && (text[n] == ' ' || text[n] == '\t');
    };
    if (keyword("newmtl")) entries.push_back({text.substr(7), {file, line_number, false, false}});
    else if (keyword("Pr")) entries.back().definition.has_roughness = true;
    else if (keyword("Pm")) entries.back().definition.has_metallic = true;
  }
  std::vector<MtlDefinition> out;
  for (size_t i = 0; i < entries.size(); ++i)
    if (!entries[i].name.empty() || i + 1 == entries.size()) out.push_back(entries[i].definition);
  return out;
}

// Exporters on Windows write texture and MTL paths with backslashes.
std::string with_forward_slashes(std::string name) {
  std::replace(name.begin(), name.end(), '\\', '/');
  return name;
}

// tinyobjloader asks this for each mtllib: the MTL is read from the OBJ's folder only,
// under safe_file's rules, and where each material came from is noted. A refused path
// is kept as the load's error (thrown once tinyobjloader returns); a missing file is a warning.
class ConfinedMtlReader : public tinyobj::MaterialReader {
 public:
  ConfinedMtlReader(const std::string& obj_path, const fs::path& folder, std::vector<MtlDefinition>& definitions,
                    std::vector<std::string>& warnings)
      : obj_path_(obj_path), folder_(folder), definitions_(definitions), warnings_(warnings) {}

  bool operator()(const std::string& name, std::vector<tinyobj::material_t>* materials,
                  std::map<std::string, int>* names, std::string* warn, std::string* err) override {
    const std::string what = obj_path_ + ": mtllib '" + name + "'";
    const std::string relative = with_forward_slashes(name);
    if (!names_file_inside_folder(relative)) return fail(what + " " + kOutsideFolder);
    const fs::path file = folder_ / relative;
    std::error_code ec;
    if (!fs::exists(fs::symlink_status(file, ec))) {
      warnings_.push_back(what + ": file not found; its materials are left out (their faces get the default material)");
      return false;
    }
    std::vector<unsigned char> bytes;
    try {
      bytes = read_file_inside(file, folder_, kMaxObjFileBytes);
    } catch (const Error& e) {
      return fail(what + ": " + e.what());
    }
    const size_t first = materials->size();
    BytesStreamBuf buffer(bytes);
    std::istream in(&buffer);
    std::string mtl_warnings;
    tinyobj::LoadMtl(names, materials, &in, &mtl_warnings, err);
    if (warn && !mtl_warnings.empty()) *warn += relative + ": " + mtl_warnings;
    std::vector<MtlDefinition> found = scan_mtl(bytes, relative);
    const size_t added = materials->size() - first;
    for (size_t k = 0; k < added; ++k)
      definitions_.push_back(found.size() == added ? found[k] : MtlDefinition{relative, 0, false, false});
    return true;
  }

  const std::string& error() const { return error_; }

 private:
  bool fail(const std::string& message) {
    if (error_.empty()) error_ = message;
    return false;
  }

  const std::string& obj_path_;
  fs::path folder_;
  std::vector<MtlDefinition>& definitions_;
  std::vector<std::string>& warnings_;
  std::string error_;
};

float largest(const tinyobj::real_t (&rgb)[3]) { return std::max({rgb[0], rgb[1], rgb[2]}); }
glm::vec3 to_vec3(const tinyobj::real_t (&rgb)[3]) { return glm::vec3(rgb[0], rgb[1], rgb[2]); }

class ObjSceneBuilder {
 public:
  ObjSceneBuilder(const std::string& path, const fs::path& folder) : path_(path), folder_(folder) {}

  Scene build() {
    scene_.path = path_;
    const std::vector<unsigned char> bytes = read_regular_file(path_, kMaxObjFileBytes);
    BytesStreamBuf buffer(bytes);
    std::istream in(&buffer);
    ConfinedMtlReader mtl_reader(path_, folder_, definitions_, scene_.warnings);
    std::string warn, err;
    const bool ok = tinyobj::LoadObj(&attrib_, &shapes_, &materials_, &warn, &err, &in, &mtl_reader, true);
    if (!mtl_reader.error().empty()) throw Error(mtl_reader.error());
    if (!ok || !err.empty()) {
      while (!err.empty() && err.back() == '\n') err.pop_back();
      throw Error(path_ + ": invalid OBJ: " + (err.empty() ? std::string("the file could not be parsed") : err));
    }
    add_warnings(warn);
    for (size_t i = 0; i < materials_.size(); ++i) scene_.materials.push_back(material(i));
    for (size_t s = 0; s < shapes_.size(); ++s) add_shape(s);
    if (scene_.primitives.empty()) throw Error(path_ + ": the scene draws no triangles (no faces with 3 or more corners)");
    for (size_t p = 0; p < scene_.primitives.size(); ++p) scene_.draws.push_back({static_cast<int>(p), glm::mat4(1.0f)});
    set_bounds_from_draws(scene_);
    return std::move(scene_);
  }

 private:
  // tinyobjloader's warnings, one line each, named by the file they came from.
  void add_warnings(const std::string& text) {
    size_t start = 0;
    while (start < text.size()) {
      size_t end = text.find('\n', start);
      if (end == std::string::npos) end = text.size();
      if (end > start) scene_.warnings.push_back(path_ + ": " + text.substr(start, end - start));
      start = end + 1;
    }
  }

  std::string material_name(size_t index) const {
    const MtlDefinition* d = index < definitions_.size() ? &definitions_[index] : nullptr;
    std::string out = "material '" + materials_[index].name + "'";
    if (d && d->line > 0) out += " (" + d->file + ":" + std::to_string(d->line) + ")";
    return out;
  }

  // MTL's Phong parameters as the kit's metallic-roughness material (handouts/README.md):
  //  - roughness: Ns is a Blinn-Phong exponent. Walter et al. (2007, "Microfacet models
  //    for refraction", sec. 5.2) match exponent n to a Beckmann lobe of width
  //    alpha = sqrt(2 / (n + 2)), which GGX of the same alpha follows closely near its
  //    peak. The kit's roughness is glTF's perceptual one, alpha = roughness^2
  //    (guards.glsl), so roughness = (2 / (Ns + 2))^(1/4): Ns 0 -> 1, Ns 1000 -> 0.21.
  //  - metallic: Phong reflects Kd diffusely and Ks specularly. A dielectric has a strong
  //    diffuse colour and a weak (about 4 %), uncoloured specular; a metal has no diffuse
  //    and a coloured specular. So a material is metallic as far as its specular
  //    outweighs its diffuse: metallic = clamp(1 - max(Kd) / max(Ks), 0, 1), 0 when Ks is
  //    black; the base colour moves from Kd towards Ks by as much (a metal's base colour
  //    is its specular colour). Blender's default export (Kd 0.8, Ks 0.5) stays dielectric.
  //  - Pr and Pm (the MTL PBR extension) replace both when given; with Pm, Kd stays the base colour.
  Material material(size_t index) {
    const tinyobj::material_t& src = materials_[index];
    const MtlDefinition definition = index < definitions_.size() ? definitions_[index] : MtlDefinition{};
    const std::string what = path_ + ": " + material_name(index);
    for (const tinyobj::real_t* values : {src.diffuse, src.specular, src.emission})
      for (int c = 0; c < 3; ++c)
        if (!std::isfinite(values[c])) throw Error(what + ": a Kd, Ks or Ke value is not finite");
    for (tinyobj::real_t value : {src.shininess, src.dissolve, src.roughness, src.metallic})
      if (!std::isfinite(value)) throw Error(what + ": an Ns, d, Tr, Pr or Pm value is not finite");

    Material m;
    m.name = src.name;
    const glm::vec3 diffuse = glm::max(to_vec3(src.diffuse), glm::vec3(0.0f));
    const glm::vec3 specular = glm::max(to_vec3(src.specular), glm::vec3(0.0f));
    const float max_specular = std::max(largest(src.specular), 0.0f);
    const float phong_metallic =
        max_specular > 0.0f ? std::clamp(1.0f - std::max(largest(src.diffuse), 0.0f) / max_specular, 0.0f, 1.0f) : 0.0f;
    const double shininess = std::max(static_cast<double>(src.shininess), 0.0);
    const float phong_roughness = static_cast<float>(std::pow(2.0 / (shininess + 2.0), 0.25));
    m.metallic_factor = definition.has_metallic ? std::clamp(static_cast<float>(src.metallic), 0.0f, 1.0f) : phong_metallic;
    m.roughness_factor = definition.has_roughness ? std::clamp(static_cast<float>(src.roughness), 0.0f, 1.0f) : phong_roughness;
    const glm::vec3 base = definition.has_metallic ? diffuse : glm::mix(diffuse, specular, phong_metallic);
    m.base_color_factor = glm::vec4(base, std::clamp(static_cast<float>(src.dissolve), 0.0f, 1.0f));
    // d < 1 (Tr > 0) is a see-through material: glTF's BLEND, which the forward pass
    // lays over what is behind it (forward_pass.h). d 1 stays OPAQUE.
    if (m.base_color_factor.a < 1.0f) m.alpha_mode = KIT_ALPHA_BLEND;
    m.emissive = glm::max(to_vec3(src.emission), glm::vec3(0.0f));

    // The maps the kit reads, each into its texture unit. "norm" names a normal map;
    // map_Bump/bump name one in most exported files too (classic MTL meant a height
    // map there; the kit reads tangent-space normals).
    struct Map {
      int unit;
      const char* keyword;
      const std::string& name;
      const tinyobj::texture_option_t& option;
    };
    const bool norm = !src.normal_texname.empty();
    const tinyobj::texture_option_t& normal_option = norm ? src.normal_texopt : src.bump_texopt;
    const Map maps[] = {{KIT_UNIT_BASE_COLOR, "map_Kd", src.diffuse_texname, src.diffuse_texopt},
                        {KIT_UNIT_EMISSIVE, "map_Ke", src.emissive_texname, src.emissive_texopt},
                        {KIT_UNIT_NORMAL_MAP, norm ? "norm" : "map_Bump", norm ? src.normal_texname : src.bump_texname,
                         normal_option}};
    for (const Map& map : maps) m.texture(map.unit).image = texture(index, map.keyword, map.name);
    // A map_Ke without Ke would be multiplied by black: the map alone is meant.
    if (m.texture(KIT_UNIT_EMISSIVE).image >= 0 && m.emissive == glm::vec3(0.0f)) m.emissive = glm::vec3(1.0f);
    m.normal_scale = static_cast<float>(normal_option.bump_multiplier);
    if (!std::isfinite(m.normal_scale)) throw Error(what + ": the -bm value is not finite");
    for (const Map& map : maps) m.texture(map.unit).uv = texture_uv(map.option, what + ": " + map.keyword);

    std::string unused;
    for (const auto& [keyword, name] : {std::pair<const char*, const std::string&>{"map_Ka", src.ambient_texname},
                                        {"map_Ks", src.specular_texname}, {"map_Ns", src.specular_highlight_texname},
                                        {"map_d", src.alpha_texname}, {"disp", src.displacement_texname},
                                        {"map_Pr", src.roughness_texname}, {"map_Pm", src.metallic_texname}})
      if (!name.empty()) unused += std::string(unused.empty() ? "" : ", ") + keyword + " '" + name + "'";
    if (!unused.empty())
      scene_.warnings.push_back(what + ": " + unused + " not used (the kit reads map_Kd, map_Ke and norm or map_Bump)");
    return m;
  }

  // A map's -o (origin offset) and -s (scale) options as the TextureUv of the kit's
  // UVs. MTL applies them to OBJ's UVs, whose v grows up: u' = s_u u + o_u in both,
  // and with the kit's v = 1 - v_obj, v' = 1 - (s_v v_obj + o_v) = s_v v + (1 - s_v - o_v).
  // The w components (3D textures) have no meaning for an image.
  static TextureUv texture_uv(const tinyobj::texture_option_t& option, const std::string& what) {
    for (int c = 0; c < 2; ++c)
      if (!std::isfinite(option.origin_offset[c]) || !std::isfinite(option.scale[c]))
        throw Error(what + ": an -o or -s value is not finite");
    const float scale_u = static_cast<float>(option.scale[0]), scale_v = static_cast<float>(option.scale[1]);
    const float offset_u = static_cast<float>(option.origin_offset[0]);
    const float offset_v = 1.0f - scale_v - static_cast<float>(option.origin_offset[1]);
    TextureUv uv;
    uv.transform = glm::mat3(scale_u, 0, 0, 0, scale_v, 0, offset_u, offset_v, 1);  // column-major
    return uv;
  }

  // The image a material's map names, loaded once per file: -1 when it names none, or
  // when the file is missing or not PNG/JPEG (a warning). A path out of the OBJ's
  // folder, or a file read_file_inside refuses, is an error.
  int texture(size_t material_index, const char* keyword, const std::string& name) {
    if (name.empty()) return -1;
    const std::string relative = with_forward_slashes(name);
    const std::string what = path_ + ": " + material_name(material_index) + ": " + keyword + " '" + name + "'";
    if (!names_file_inside_folder(relative)) throw Error(what + " " + kOutsideFolder);
    auto known = image_of_file_.find(relative);
    if (known != image_of_file_.end()) return known->second;
    const fs::path file = folder_ / relative;
    std::error_code ec;
    int index = -1;
    if (!fs::exists(fs::symlink_status(file, ec))) {
      scene_.warnings.push_back(what + ": file not found; the material is drawn without it");
    } else {
      std::vector<unsigned char> bytes;
      try {
        bytes = read_file_inside(file, folder_, kMaxObjFileBytes);
      } catch (const Error& e) {
        throw Error(what + ": " + e.what());
      }
      try {
        const TextureHeader header = read_texture_header(bytes.data(), bytes.size(), what);
        scene_.images.push_back({what, header.width, header.height, std::move(bytes), {}});
        index = static_cast<int>(scene_.images.size()) - 1;
      } catch (const Error& e) {
        scene_.warnings.push_back(std::string(e.what()) + "; the material is drawn without it");
      }
    }
    image_of_file_[relative] = index;
    return index;
  }

  // A primitive being gathered: one per object and material, each OBJ corner
  // (position, UV and normal index) one vertex.
  using CornerKey = std::array<int, 3>;  // position, UV and normal index (-1: absent)
  struct CornerHash {
    size_t operator()(const CornerKey& k) const {
      return std::hash<uint64_t>()((static_cast<uint64_t>(static_cast<uint32_t>(k[0])) << 32) ^
                                   (static_cast<uint64_t>(static_cast<uint32_t>(k[1])) << 16) ^
                                   static_cast<uint32_t>(k[2]));
    }
  };
  struct PrimitiveBuilder {
    Primitive primitive;
    std::unordered_map<CornerKey, uint32_t, CornerHash> vertex_of_corner;
    bool some_normals = false, missing_normals = false;
  };

  void add_shape(size_t shape_index) {
    const tinyobj::shape_t& shape = shapes_[shape_index];
    const tinyobj::mesh_t& mesh = shape.mesh;
    const std::string object = "object '" + shape.name + "'";
    std::map<int, PrimitiveBuilder> by_material;
    std::vector<int> material_order;
    size_t offset = 0, skipped = 0;
    for (size_t face = 0; face < mesh.num_face_vertices.size(); ++face) {
      const size_t corners = static_cast<size_t>(mesh.num_face_vertices[face]);
      if (corners > mesh.indices.size() - offset)
        throw Error(path_ + ": " + object + " face " + std::to_string(face + 1) + ": its corner list runs past the file's indices");
      if (corners != 3) {  // triangulation leaves only faces it could not split
        ++skipped;
        offset += corners;
        continue;
      }
      int material = face < mesh.material_ids.size() ? mesh.material_ids[face] : -1;
      if (material < -1 || material >= static_cast<int>(materials_.size()))
        throw Error(path_ + ": " + object + " face " + std::to_string(face + 1) + ": material index " +
                    std::to_string(material) + " does not exist");
      if (material < 0) material = default_material();
      auto [slot, added] = by_material.try_emplace(material);
      if (added) material_order.push_back(material);
      for (size_t k = 0; k < 3; ++k) add_corner(slot->second, mesh.indices[offset + k], object, face);
      offset += 3;
    }
    if (skipped > 0)
      scene_.warnings.push_back(path_ + ": " + object + ": " + std::to_string(skipped) +
                                " faces with fewer than 3 corners are not drawn");
    for (int material : material_order) {
      PrimitiveBuilder& b = by_material[material];
      Primitive& prim = b.primitive;
      prim.material = material;
      prim.name = object + " " + material_name_of(material);
      if (b.missing_normals) {
        if (b.some_normals)
          scene_.warnings.push_back(path_ + ": " + prim.name +
                                    ": some faces have normals (vn) and some do not: flat normals for all of them");
        use_flat_normals(prim);
      }
      const Material& m = scene_.materials.at(static_cast<size_t>(material));
      generate_tangents(prim.vertices, prim.indices, m.texture(KIT_UNIT_NORMAL_MAP).uv);
      prim.tangents_generated = true;
      set_bounds_from_vertices(prim);
      scene_.primitives.push_back(std::move(prim));
    }
  }

  std::string material_name_of(int material) const {
    return material == default_material_ ? "without material" : material_name(static_cast<size_t>(material));
  }

  int default_material() {
    if (default_material_ < 0) {
      scene_.materials.push_back(default_obj_material());
      default_material_ = static_cast<int>(scene_.materials.size()) - 1;
    }
    return default_material_;
  }

  void add_corner(PrimitiveBuilder& b, const tinyobj::index_t& corner, const std::string& object, size_t face) {
    const size_t positions = attrib_.vertices.size() / 3, uvs = attrib_.texcoords.size() / 2,
                 normals = attrib_.normals.size() / 3;
    const std::string where = path_ + ": " + object + " face " + std::to_string(face + 1);
    auto check = [&](int index, size_t count, const char* kind, bool optional) {
      const bool valid = (optional && index == -1) || (index >= 0 && static_cast<size_t>(index) < count);
      if (!valid)
        throw Error(where + ": " + kind + " index " + std::to_string(index < 0 ? index : index + 1) +
                    " does not exist (the file has " + std::to_string(count) + ")");
    };
    check(corner.vertex_index, positions, "position (v)", false);
    check(corner.texcoord_index, uvs, "texture coordinate (vt)", true);
    check(corner.normal_index, normals, "normal (vn)", true);
    (corner.normal_index >= 0 ? b.some_normals : b.missing_normals) = true;
    const CornerKey key{corner.vertex_index, corner.texcoord_index, corner.normal_index};
    auto found = b.vertex_of_corner.find(key);
    if (found != b.vertex_of_corner.end()) {
      b.primitive.indices.push_back(found->second);
      return;
    }
    if (b.primitive.vertices.size() >= std::numeric_limits<uint32_t>::max())
      throw Error(where + ": the object has more vertices than 32-bit indices can address");
    Vertex v{};
    const size_t p = static_cast<size_t>(corner.vertex_index);
    v.position = glm::vec3(attrib_.vertices[3 * p], attrib_.vertices[3 * p + 1], attrib_.vertices[3 * p + 2]);
    if (corner.normal_index >= 0) {
      const size_t n = static_cast<size_t>(corner.normal_index);
      v.normal = glm::vec3(attrib_.normals[3 * n], attrib_.normals[3 * n + 1], attrib_.normals[3 * n + 2]);
    }
    if (corner.texcoord_index >= 0) {
      const size_t t = static_cast<size_t>(corner.texcoord_index);
      v.texcoord = glm::vec2(attrib_.texcoords[2 * t], 1.0f - attrib_.texcoords[2 * t + 1]);  // OBJ's v grows up
    }
    // `v x y z r g b`: a linear vertex colour, like glTF's COLOR_0 (tinyobjloader
    // gives every vertex one, white where the file has none, once any vertex has one).
    glm::vec3 color(1.0f);
    if (attrib_.colors.size() == attrib_.vertices.size())
      color = glm::vec3(attrib_.colors[3 * p], attrib_.colors[3 * p + 1], attrib_.colors[3 * p + 2]);
    if (!std::isfinite(glm::dot(v.position, v.position)) || !std::isfinite(glm::dot(v.normal, v.normal)) ||
        !std::isfinite(glm::dot(v.texcoord, v.texcoord)) || !std::isfinite(glm::dot(color, color)))
      throw Error(where + ": a position, normal, texture coordinate or vertex colour is not finite (NaN or Inf)");
    for (int c = 0; c < 3; ++c) v.color[c] = vertex_color_component(color[c]);
    const uint32_t index = static_cast<uint32_t>(b.primitive.vertices.size());
    b.primitive.vertices.push_back(v);
    b.primitive.indices.push_back(index);
    b.vertex_of_corner.emplace(key, index);
  }

  const std::string& path_;
  fs::path folder_;
  Scene scene_;
  tinyobj::attrib_t attrib_;
  std::vector<tinyobj::shape_t> shapes_;
  std::vector<tinyobj::material_t> materials_;
  std::vector<MtlDefinition> definitions_;  // parallel to materials_
  std::map<std::string, int> image_of_file_;
  int default_material_ = -1;
};

}  // namespace

Scene load_obj_scene(const std::string& path) {
  std::error_code ec;
  if (!fs::exists(fs::symlink_status(path, ec))) throw Error(path + ": scene file not found");
  return ObjSceneBuilder(path, fs::absolute(path).parent_path()).build();
}

#endif

}  // namespace kit
