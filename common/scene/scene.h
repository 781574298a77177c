#pragma once
// glTF 2.0 scenes: loaded by tinygltf into plain CPU structures (validated,
// flattened node hierarchy, generated tangents), then uploaded to GL.
// The glTF loader is gltf_loader.h's (gltf_loader.cpp, gltf_builder.cpp,
// gltf_accessors.cpp), the OBJ loader obj_scene.h's, SceneGpu's upload scene_gpu.cpp.
#include <glm/glm.hpp>

#include <array>
#include <optional>
#include <string>
#include <vector>

#include "gbuffer_layout.h"
#include "gl/gl_objects.h"
#include "images/texture_compression.h"
#include "images/texture_decode.h"

namespace kit {

// A glTF sampler with its filters and wrap modes (GL enum values, which glTF
// uses too); the default is glTF's when a texture names none: repeat, and
// trilinear filtering for "auto".
struct TextureSampler {
  GLenum min_filter = GL_LINEAR_MIPMAP_LINEAR;
  GLenum mag_filter = GL_LINEAR;
  GLenum wrap_s = GL_REPEAT, wrap_t = GL_REPEAT;
};

// How a material texture finds its UV, as glTF's texture reference says: its
// texCoord picks a UV set, which the loader puts in one of the two UV slots a
// Vertex carries (texcoord, texcoord1), and KHR_texture_transform maps it. The
// geometry pass does the same per fragment (kit_texture_uv, material_uniforms.glsl).
struct TextureUv {
  int slot = 0;                // 0: Vertex::texcoord, 1: Vertex::texcoord1
  glm::mat3 transform{1.0f};   // KHR_texture_transform's matrix (texture_transform_matrix)
  glm::vec2 of(const Vertex& v) const;  // the UV the texture samples at the vertex
};

// KHR_texture_transform's {offset, rotation, scale} as the matrix TextureUv holds
// (column-major; the UV is scaled, then rotated, then offset), in the direction the
// Khronos sample models and viewers turn it in glTF's UV space, whose v grows down
// the image:
//   u' = ox + cos(r) sx u + sin(r) sy v,   v' = oy - sin(r) sx u + cos(r) sy v.
// The GLSL listing in the extension's README turns the other way (glTF issue #1563).
glm::mat3 texture_transform_matrix(glm::vec2 offset, float rotation, glm::vec2 scale);

// One of a material's textures: its image and sampler, and which of the vertex's two
// UV slots it reads with what KHR_texture_transform (TextureUv).
struct MaterialTexture {
  int image = -1;    // index into Scene::images, -1 when absent
  int sampler = -1;  // index into Scene::samplers, -1: the default TextureSampler
  TextureUv uv;
};

// A material has a texture for each of the geometry pass's material units, which
// number them from 0 (gbuffer_layout.h).
constexpr int kMaterialTextureCount = 4;
static_assert(KIT_UNIT_BASE_COLOR == 0 && KIT_UNIT_METALLIC_ROUGHNESS == 1 && KIT_UNIT_NORMAL_MAP == 2 &&
                  KIT_UNIT_EMISSIVE == 3,
              "Material::textures is indexed by the material texture units");
// Whether the texture at `unit` holds colour, stored sRGB-encoded (base colour,
// emission), rather than data read linearly (metallic-roughness, normals).
constexpr bool material_texture_is_color(int unit) { return unit == KIT_UNIT_BASE_COLOR || unit == KIT_UNIT_EMISSIVE; }

struct Material {
  glm::vec4 base_color_factor{1.0f};
  float metallic_factor = 1.0f;
  float roughness_factor = 1.0f;
  glm::vec3 emissive{0.0f};  // emissiveFactor * KHR_materials_emissive_strength
  float normal_scale = 1.0f;
  int alpha_mode = 0;          // KIT_ALPHA_OPAQUE, KIT_ALPHA_MASK or KIT_ALPHA_BLEND (gbuffer_layout.h)
  float alpha_cutoff = 0.5f;   // glTF alphaCutoff (its default), for KIT_ALPHA_MASK
  bool double_sided = false;   // glTF doubleSided: drawn without back-face culling
  // The material's textures, indexed by the unit the geometry pass binds each to
  // (KIT_UNIT_BASE_COLOR, ..._METALLIC_ROUGHNESS, ..._NORMAL_MAP, ..._EMISSIVE):
  // texture(KIT_UNIT_NORMAL_MAP) is the normal map.
  std::array<MaterialTexture, kMaterialTextureCount> textures;
  MaterialTexture& texture(int unit) { return textures.at(static_cast<size_t>(unit)); }
  const MaterialTexture& texture(int unit) const { return textures.at(static_cast<size_t>(unit)); }
  // The glTF UV set (TEXCOORD_n) the loader puts in each of the vertex's two UV
  // slots: those the material's textures name, -1 for a slot none reads.
  std::array<int, 2> uv_set_of_slot{0, -1};
  std::string name;
};

struct Primitive {
  std::vector<Vertex> vertices;
  std::vector<uint32_t> indices;
  int material = -1;             // -1: the glTF default material
  bool tangents_generated = false;
  glm::vec3 bounds_min{0.0f}, bounds_max{0.0f};
  std::string name;              // "mesh 'x' primitive 0"
};

struct DrawItem {
  int primitive;
  glm::mat4 world;
  // A world matrix with a negative determinant mirrors the mesh, which turns its
  // counter-clockwise (front) triangles clockwise: draw_scene draws it with
  // glFrontFace(GL_CW), or back-face culling would remove its front.
  bool mirrored() const { return glm::determinant(glm::mat3(world)) < 0.0f; }
};

struct Light {
  int type = 0;                  // KIT_LIGHT_POINT, KIT_LIGHT_SPOT or KIT_LIGHT_DIRECTIONAL
  glm::vec3 position{0.0f};      // its node's; a directional light's light comes from no point
  glm::vec3 direction{0, 0, -1}; // where a spot or directional light points: its node's world -Z (unit)
  glm::vec3 color{1.0f};
  float intensity = 1.0f;        // glTF units: candela; lux (illuminance) for a directional light
  float range = 0.0f;            // 0: unlimited (always, for a directional light)
  float inner_cone = 0.0f;       // radians
  float outer_cone = 0.7853982f; // radians (glTF default pi/4)
};

// A glTF camera placed by its node: perspective (yfov, aspect_ratio) or
// orthographic (xmag, ymag), both with znear and zfar.
struct Camera {
  glm::mat4 view{1.0f};
  glm::vec3 position{0.0f};
  bool orthographic = false;
  float yfov = 0.8f, znear = 0.1f, zfar = 100.0f;
  float aspect_ratio = 0.0f;       // perspective: width / height the file asks for; 0: the window's
  float xmag = 1.0f, ymag = 1.0f;  // orthographic: half the view's width and height
  // glTF 2.0's projection matrices ("Projection Matrices"); `window_aspect` is used
  // by a perspective camera without aspect_ratio. A perspective camera without zfar
  // gets a finite one (1000) when loaded, as the kit's depth views need one.
  glm::mat4 projection(float window_aspect) const;
};

struct Scene {
  std::string path;
  std::vector<SceneImage> images;
  std::vector<TextureSampler> samplers;
  std::vector<Material> materials;
  std::vector<Primitive> primitives;
  std::vector<DrawItem> draws;
  std::vector<Light> lights;
  // Every node with a camera, in the order the walk of the scene's node tree
  // (depth first, from its roots) meets them; `camera` is the first, the default view.
  std::vector<Camera> cameras;
  std::optional<Camera> camera;
  glm::vec3 bounds_min{0.0f}, bounds_max{0.0f};  // world space, over all draws
  // What was loaded differently from the file (points and lines left out, ...);
  // the programs print each once.
  std::vector<std::string> warnings;
};

// The most draw items a scene may make (primitives of mesh nodes, times the
// instances of EXT_mesh_gpu_instancing): the renderer issues one GL draw each.
constexpr size_t kMaxSceneDraws = size_t{1} << 18;

// Loads and validates a .gltf/.glb file (an .obj goes to load_obj_scene, obj_scene.h). Any problem throws kit::Error whose
// message starts with the path and says what is wrong; nothing crashes.
Scene load_scene(const std::string& path);

// Fills Vertex::tangent from positions, normals and the UVs the normal texture
// samples (`normal_uv`): per-triangle UV derivatives, Gram-Schmidt, handedness in
// w. Degenerate UVs still give a unit tangent perpendicular to the normal.
void generate_tangents(std::vector<Vertex>& vertices, const std::vector<uint32_t>& indices,
                       const TextureUv& normal_uv = {});

// A vertex colour component (glTF COLOR_0, OBJ vertex colour; linear) as
// Vertex::color stores it: clamped to [0, 1], then round(value * 65535).
uint16_t vertex_color_component(float value);

// Flat normals for a primitive whose file gives none (glTF requires them; OBJ
// faces without vn get the same): every triangle gets its own three vertices
// carrying its plane's normal. Call before generate_tangents.
void use_flat_normals(Primitive& primitive);

// Primitive::bounds_min/max from its vertices' positions (every loader's primitives).
void set_bounds_from_vertices(Primitive& primitive);
// Frees what SceneGpu copies to GL and nothing reads afterwards: the primitives' vertices
// and indices (bounds and materials stay) and the images' bytes, and hands the memory
// back to the system. For a program that has built its one SceneGpu from `scene`
// (kit-render): a SceneGpu made from it afterwards would be empty.
void release_uploaded_data(Scene& scene);
// Scene::bounds_min/max over every draw: the 8 corners of its primitive's bounds,
// transformed by the draw's world matrix.
void set_bounds_from_draws(Scene& scene);

// A camera that frames the scene's bounds, for scenes without a camera.
Camera framing_camera(const Scene& scene);

// The view a program renders: the scene's camera `index` (Scene::cameras), or
// with index -1 its first camera, else framing_camera. Throws kit::Error naming
// the file and how many cameras it has when there is no camera `index`.
Camera chosen_camera(const Scene& scene, int index);

// GL resources of a scene: one Mesh per primitive, the textures materials use (colour
// data, base colour and emission, as sRGB; normal and metallic-roughness data as linear)
// and a GL sampler per glTF sampler. The renderer binds them per material.
class SceneGpu {
 public:
  // `compression`: whether textures of at least kLargeTextureTexels are uploaded as S3TC
  // blocks (decide_texture_compression); smaller ones and normal maps never are.
  explicit SceneGpu(const Scene& scene, TextureCompression compression = TextureCompression::Auto);
  // What was decided for the textures, and why (kit-render --timings prints it).
  const TextureCompressionDecision& texture_compression() const { return compression_; }
  const Mesh& mesh(int primitive) const { return meshes_[static_cast<size_t>(primitive)]; }
  // Scene::images[image] as sampled in one colour space (sRGB or linear); image -1 (no
  // texture): white in that colour space. An image no material samples in that space has
  // an empty texture.
  const Texture2D& texture(int image, bool srgb) const;
  const Texture2D& flat_normal() const { return flat_normal_; }
  // The GL sampler of Scene::samplers[index]; index -1: the default TextureSampler.
  const Sampler& sampler(int index) const;

 private:
  std::vector<Mesh> meshes_;
  std::vector<Sampler> samplers_;
  Sampler default_sampler_;
  std::vector<Texture2D> srgb_, linear_;
  Texture2D white_srgb_, white_, flat_normal_;  // placeholder_texture
  TextureCompressionDecision compression_;
};

}  // namespace kit
