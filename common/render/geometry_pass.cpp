// The geometry pass's draw loop (renderer.h): each draw item's matrices, material uniforms,
// textures and face state, over the scene's draws with one program or a variant per material.
#include "render/renderer.h"

#include <glm/gtc/matrix_inverse.hpp>

#include <algorithm>

#include "gbuffer_layout.h"
#include "render/forward_pass.h"
#include "scene/mesh_optimize.h"

namespace kit {

const Material& draw_material(const Scene& scene, const DrawItem& draw) {
  static const Material kDefaultMaterial{};
  const Primitive& prim = scene.primitives[static_cast<size_t>(draw.primitive)];
  return prim.material >= 0 ? scene.materials[static_cast<size_t>(prim.material)] : kDefaultMaterial;
}

void draw_item(const Program& geometry, const Scene& scene, const SceneGpu& gpu, const DrawItem& d) {
  const Material& m = draw_material(scene, d);
  geometry.set("u_model", d.world);
  geometry.set("u_normal_matrix", glm::inverseTranspose(glm::mat3(d.world)));
  geometry.set("u_base_color_factor", m.base_color_factor);
  geometry.set("u_metallic_factor", m.metallic_factor);
  geometry.set("u_roughness_factor", m.roughness_factor);
  geometry.set("u_emissive_factor", m.emissive);
  geometry.set("u_normal_scale", m.normal_scale);
  geometry.set("u_has_normal_texture", m.texture(KIT_UNIT_NORMAL_MAP).image >= 0);
  geometry.set("u_alpha_mode", m.alpha_mode);
  geometry.set("u_alpha_cutoff", m.alpha_cutoff);
  geometry.set("u_double_sided", m.double_sided);
  // Each texture's UV slot and KHR_texture_transform, indexed by its unit (kit_texture_uv).
  static const char* const kUvSlot[] = {"u_texture_uv_slot[0]", "u_texture_uv_slot[1]", "u_texture_uv_slot[2]",
                                        "u_texture_uv_slot[3]"};
  static const char* const kUvTransform[] = {"u_texture_uv_transform[0]", "u_texture_uv_transform[1]",
                                             "u_texture_uv_transform[2]", "u_texture_uv_transform[3]"};
  static_assert(kMaterialTextureCount == 4, "u_texture_uv_* has an entry per material texture unit");
  for (int unit = 0; unit < kMaterialTextureCount; ++unit) {
    const MaterialTexture& t = m.texture(unit);
    geometry.set(kUvSlot[unit], t.uv.slot);
    geometry.set(kUvTransform[unit], t.uv.transform);
    // A missing normal map reads as the flat normal; other missing textures as white.
    const bool flat = unit == KIT_UNIT_NORMAL_MAP && t.image < 0;
    (flat ? gpu.flat_normal() : gpu.texture(t.image, material_texture_is_color(unit))).bind(unit);
    gpu.sampler(t.sampler).bind(unit);
  }
  glFrontFace(d.mirrored() ? GL_CW : GL_CCW);
  // A double-sided material shows its back faces too (material_modes.glsl flips their normal).
  if (m.double_sided) glDisable(GL_CULL_FACE); else glEnable(GL_CULL_FACE);
  gpu.mesh(d.primitive).draw();
}

void end_scene_draws() {
  glFrontFace(GL_CCW);  // GL's default, which every other pass expects
  glEnable(GL_CULL_FACE);  // as begin_geometry_pass_on left it
  // Units other passes may reuse sample with their textures' own settings again.
  for (int unit : {KIT_UNIT_BASE_COLOR, KIT_UNIT_METALLIC_ROUGHNESS, KIT_UNIT_NORMAL_MAP, KIT_UNIT_EMISSIVE})
    Sampler::unbind(unit);
}

void note_drawn(std::vector<const Program*>* drawn, const Program& program) {
  if (drawn && std::find(drawn->begin(), drawn->end(), &program) == drawn->end()) drawn->push_back(&program);
}

namespace {
// draw_scene's loop: `program_for(d)` draws d, put in use when it is another than the last draw's.
template <typename ProgramFor>
void draw_scene_with(const ProgramFor& program_for, const Scene& scene, const SceneGpu& gpu,
                     const glm::mat4& view_projection, bool frustum_culling, DrawSet set,
                     std::vector<const Program*>* drawn) {
  const Frustum frustum = frustum_from(view_projection);
  const Program* current = nullptr;
  for (const DrawItem& d : scene.draws) {
    if (set == DrawSet::AllButBlend && is_blend_draw(scene, d)) continue;  // the forward pass draws it
    const Primitive& prim = scene.primitives[static_cast<size_t>(d.primitive)];
    // A draw wholly outside the view adds no fragment: skipping it saves its vertex work.
    if (frustum_culling && !intersects(frustum, prim.bounds_min, prim.bounds_max, d.world)) continue;
    const Program& program = program_for(d);
    if (&program != current) {
      program.use();
      current = &program;
      note_drawn(drawn, program);
    }
    draw_item(program, scene, gpu, d);
  }
  end_scene_draws();
}
}  // namespace

void draw_scene(const Program& geometry, const Scene& scene, const SceneGpu& gpu,
                const glm::mat4& view_projection, bool frustum_culling, DrawSet set) {
  draw_scene_with([&](const DrawItem&) -> const Program& { return geometry; }, scene, gpu, view_projection,
                  frustum_culling, set, nullptr);
}

void draw_scene(const GeometryPrograms& geometry, const Scene& scene, const SceneGpu& gpu,
                const glm::mat4& view_projection, bool frustum_culling, DrawSet set,
                std::vector<const Program*>* drawn) {
  draw_scene_with([&](const DrawItem& d) -> const Program& { return geometry.for_draw(scene, d); }, scene, gpu,
                  view_projection, frustum_culling, set, drawn);
}

}  // namespace kit
