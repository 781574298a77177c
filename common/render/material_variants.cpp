#include "render/material_variants.h"

#include <algorithm>

#include "base/error.h"
#include "gbuffer_layout.h"
#include "render/renderer.h"

namespace kit {

unsigned material_features(const Material& m) {
  unsigned features = 0;
  for (const MaterialTexture& t : m.textures) {
    if (t.uv.slot != 0) features |= kMaterialUv1;
    if (t.uv.transform != glm::mat3(1.0f)) features |= kMaterialUvTransform;
  }
  if (m.alpha_mode == KIT_ALPHA_MASK) features |= kMaterialAlphaMask;
  return features;
}

unsigned draw_features(const Scene& scene, const DrawItem& draw) { return material_features(draw_material(scene, draw)); }

std::vector<std::pair<std::string, bool>> material_variant_defines(unsigned features) {
  return {{kMaterialVariantDefine, true},
          {"KIT_HAS_UV1", (features & kMaterialUv1) != 0},
          {"KIT_HAS_UV_TRANSFORM", (features & kMaterialUvTransform) != 0},
          {"KIT_HAS_ALPHA_MASK", (features & kMaterialAlphaMask) != 0}};
}

std::string material_variant_name(unsigned features) {
  std::string name;
  for (const auto& [bit, word] : {std::pair<unsigned, const char*>{kMaterialUv1, "uv1"},
                                  {kMaterialUvTransform, "uv-transform"}, {kMaterialAlphaMask, "alpha-mask"}})
    if (features & bit) name += (name.empty() ? "" : "+") + std::string(word);
  return name.empty() ? "minimal" : name;
}

std::vector<unsigned> GeometryPrograms::feature_sets(const Scene& scene) {
  std::vector<unsigned> sets;
  for (const DrawItem& d : scene.draws) sets.push_back(draw_features(scene, d));
  if (sets.empty()) sets.push_back(0);
  std::sort(sets.begin(), sets.end());
  sets.erase(std::unique(sets.begin(), sets.end()), sets.end());
  return sets;
}

GeometryPrograms::GeometryPrograms(const ShaderLibrary& library, const std::vector<unsigned>& feature_sets,
                                   const std::string& vertex, const std::string& fragment,
                                   const GeometryPrograms* previous) {
  for (unsigned features : feature_sets) {
    ShaderLibrary variant = library;
    variant.set_defines(material_variant_defines(features));
    const auto old = previous ? previous->programs_.find(features) : programs_.end();
    if (previous && old != previous->programs_.end() && old->second.built_from(variant, vertex, fragment)) {
      kept_.push_back(features);
      continue;
    }
    programs_.emplace(features, make_program(variant, vertex, fragment));
    ++built_;
  }
}

void GeometryPrograms::keep_from(GeometryPrograms& previous) {
  for (unsigned features : kept_) programs_[features] = std::move(previous.programs_.at(features));
  kept_.clear();
}

const Program& GeometryPrograms::for_features(unsigned features) const {
  const auto it = programs_.find(features);
  if (it == programs_.end())
    throw Error("no geometry program was built for the material variant " + material_variant_name(features));
  return it->second;
}

const Program& GeometryPrograms::for_draw(const Scene& scene, const DrawItem& draw) const {
  const unsigned features = draw_features(scene, draw);
  if (!programs_.count(features) && programs_.count(kMaterialAllFeatures)) return for_features(kMaterialAllFeatures);
  return for_features(features);
}

std::vector<const Program*> GeometryPrograms::all() const {
  std::vector<const Program*> out;
  for (const auto& [features, program] : programs_) out.push_back(&program);
  return out;
}

}  // namespace kit
