#pragma once
// The geometry pass's program variants: the material helpers lab shaders call
// (kit_base_color_uv and the other kit_*_uv, kit_alpha_discard; material_uniforms.glsl,
// material_modes.glsl) compiled for what a draw's material uses, as glTF-Sample-Viewer
// compiles its shaders with feature defines. A draw whose textures all read UV slot 0
// untransformed, whose material is not MASK, is drawn by a program whose helpers return
// v_texcoords.xy and discard nothing: no per-texture slot choice or 3x3 transform per
// fragment, and no discard, which on llvmpipe moves the depth test after the shader
// for every fragment of the draw. The helpers keep their names and give the same values
// in every variant; lab shaders never change.
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "gl/gl_objects.h"
#include "scene/scene.h"
#include "gl/shader_source.h"

namespace kit {

// What a material needs of the material path, one bit each.
enum MaterialFeature : unsigned {
  kMaterialUv1 = 1u << 0,          // KIT_HAS_UV1: some texture reads UV slot 1 (Vertex::texcoord1)
  kMaterialUvTransform = 1u << 1,  // KIT_HAS_UV_TRANSFORM: some texture has a KHR_texture_transform
  kMaterialAlphaMask = 1u << 2,    // KIT_HAS_ALPHA_MASK: glTF alphaMode MASK
  kMaterialAllFeatures = kMaterialUv1 | kMaterialUvTransform | kMaterialAlphaMask,
};

// Defined in the geometry programs the renderer builds per variant: the KIT_HAS_*
// defines then say which features the helpers compile. A program built without it
// (kit-bench, tests) compiles every feature, as all programs did before variants.
constexpr const char* kMaterialVariantDefine = "KIT_MATERIAL_VARIANT";

// The features `m` uses. Every texture's UV counts, whether or not the material has that
// texture: a lab shader may sample one texture at another's UV (a mistake the grader
// must see as it was), so a variant leaves out only what no helper call could return.
unsigned material_features(const Material& m);
// The features of the material `draw` is drawn with (draw_material).
unsigned draw_features(const Scene& scene, const DrawItem& draw);
// kMaterialVariantDefine on, and each KIT_HAS_* define on or off as `features` says.
std::vector<std::pair<std::string, bool>> material_variant_defines(unsigned features);
// "uv1+uv-transform+alpha-mask", or "minimal" for no feature: how messages name a variant.
std::string material_variant_name(unsigned features);

// The geometry pass's programs for a scene: one per feature set its draws use, each
// built from the same vertex and fragment shader with material_variant_defines.
class GeometryPrograms {
 public:
  GeometryPrograms() = default;
  // Every feature set among `scene`'s draws (at least one: a scene without draws gets
  // the minimal variant), sorted.
  static std::vector<unsigned> feature_sets(const Scene& scene);
  // Builds the variants `feature_sets` lists from `library` (make_program), but for those
  // of `previous` whose shaders assemble to the same texts (Program::built_from): they are
  // left for keep_from to take over once every other program of a build has compiled, so
  // that a failure leaves `previous` whole. Throws kit::Error at the first that fails.
  GeometryPrograms(const ShaderLibrary& library, const std::vector<unsigned>& feature_sets, const std::string& vertex,
                   const std::string& fragment, const GeometryPrograms* previous);
  // Takes over the variants of `previous` the constructor left to it.
  void keep_from(GeometryPrograms& previous);
  // Whether every variant is one the constructor left to keep_from (nothing was built).
  bool all_kept() const { return built_ == 0; }

  // The program that draws `draw`: its features' variant, else the variant with every
  // feature (which draws any material); throws kit::Error when neither was built.
  const Program& for_draw(const Scene& scene, const DrawItem& draw) const;
  const Program& for_features(unsigned features) const;
  // Every variant, in feature order.
  std::vector<const Program*> all() const;
  bool empty() const { return programs_.empty() && kept_.empty(); }

 private:
  std::map<unsigned, Program> programs_;
  std::vector<unsigned> kept_;  // left to keep_from
  size_t built_ = 0;
};

}  // namespace kit
