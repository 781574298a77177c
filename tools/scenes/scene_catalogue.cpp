#include "scene_catalogue.h"

#include <cmath>
#include <cstdint>
#include <fstream>
#include <stdexcept>
#include <string>
#include <utility>

#include "environments.h"
#include "gltf_scene_writer.h"
#include "scene_images.h"
#include "scene_math.h"
#include "scene_meshes.h"

namespace kit_scenes {

namespace fs = std::filesystem;

namespace {

struct Textures {
  Image8 checker = make_checker();
  Image8 brick_color = make_brick_color();
  Image8 brick_normal = make_brick_normal();
};

// A material of factors alone: no texture, opaque, single-sided.
MaterialDesc plain_material(const std::string& name, glm::dvec4 base_color, double roughness,
                            double metallic = 0.0) {
  MaterialDesc m;
  m.name = name;
  m.base_color = base_color;
  m.roughness = roughness;
  m.metallic = metallic;
  return m;
}

// Plain grey with the brick normal map: the bricks show up through shading alone.
MaterialDesc normal_mapped_grey(int normal_texture) {
  MaterialDesc m = plain_material("normal_mapped_grey", glm::dvec4(0.75, 0.75, 0.75, 1.0), 0.5);
  m.normal_texture = normal_texture;
  m.normal_scale = 1.0;
  return m;
}

// The lit scenes' 12 x 12 m grey floor (base colour 0.6) at y = 0, facing up.
void add_grey_floor(GltfSceneWriter& b, double roughness) {
  const Geometry floor = b.add_geometry(make_quad({1, 0, 0}, {0, 0, -1}, {12, 12}, {1, 1}, false));
  const MaterialDesc grey = plain_material("grey_floor", glm::dvec4(0.6, 0.6, 0.6, 1.0), roughness);
  b.add_mesh_node("floor", {0, 0, 0}, floor, b.add_material(grey));
}

// ---------------------------------------------------------------------------
// Scenes

GltfSceneWriter build_default_scene(const Textures& tex) {
  GltfSceneWriter b("default");
  const glm::vec3 x(1, 0, 0), y(0, 1, 0), z(0, 0, 1);

  // Floor: 10 x 10 m; the 4-cell checker repeats 5 times, so each square is 0.5 m.
  MaterialDesc floor_mat;
  floor_mat.name = "floor_checker";
  floor_mat.roughness = 0.8;
  floor_mat.base_color_texture = b.add_texture("checker.png", tex.checker);
  const Geometry floor = b.add_geometry(make_quad(x, -z, {10, 10}, {5, 5}, false));
  b.add_mesh_node("floor", {0, 0, 0}, floor, b.add_material(floor_mat));

  // Back wall: 8 x 4 m at z = -4, one brick texture tile per 2 m.
  const int brick_normal = b.add_texture("brick_normal.png", tex.brick_normal);
  MaterialDesc wall_mat;
  wall_mat.name = "brick_wall";
  wall_mat.roughness = 0.9;
  wall_mat.base_color_texture = b.add_texture("brick_color.png", tex.brick_color);
  wall_mat.normal_texture = brick_normal;
  wall_mat.normal_scale = 1.0;
  const Geometry wall = b.add_geometry(make_quad(x, y, {8, 4}, {4, 2}, false));
  b.add_mesh_node("back_wall", {0, 2, -4}, wall, b.add_material(wall_mat));

  // Material spheres: parent -> row -> sphere, so the loader has to compose transforms.
  const Geometry sphere = b.add_geometry(make_sphere(0.35f, 32, 16, {2, 1}, true));
  const int parent = b.add_node({"sphere_rows", {0, 0.5, -1}});
  const int row_dielectric = b.add_node({"row_dielectric"}, parent);
  const int row_metal = b.add_node({"row_metal", {0, 0.9, 0}}, parent);
  const double roughness[5] = {0.0, 0.25, 0.5, 0.75, 1.0};
  for (int i = 0; i < 5; ++i) {
    const glm::dvec3 offset(-2.0 + i, 0.0, 0.0);
    const std::string suffix = "_r" + std::to_string(i * 25);
    MaterialDesc dielectric;
    dielectric.name = "dielectric" + suffix;
    dielectric.base_color = glm::dvec4(0.8, 0.15, 0.1, 1.0);
    dielectric.metallic = 0.0;
    dielectric.roughness = roughness[i];
    const std::string d_name = "sphere_dielectric" + suffix;
    b.add_mesh_node(d_name, offset, sphere, b.add_material(dielectric), row_dielectric);
    MaterialDesc metal;
    metal.name = "gold" + suffix;
    metal.base_color = glm::dvec4(1.0, 0.766, 0.336, 1.0);
    metal.metallic = 1.0;
    metal.roughness = roughness[i];
    const std::string m_name = "sphere_gold" + suffix;
    b.add_mesh_node(m_name, offset, sphere, b.add_material(metal), row_metal);
  }

  // Left panel facing +x, image mirrored left-right: its tangent is +z with w = -1.
  const int grey = b.add_material(normal_mapped_grey(brick_normal));
  const Geometry panel = b.add_geometry(make_quad(-z, y, {1.5, 1.5}, {1, 1}, true));
  b.add_mesh_node("mirrored_panel", {-3.5, 1.0, -1.5}, panel, grey);

  // Normal-mapped sphere without TANGENT: the loader must generate them.
  const Geometry bare = b.add_geometry(make_sphere(0.5f, 32, 16, {2, 1}, false));
  b.add_mesh_node("sphere_no_tangents", {3.2, 0.5, -1.0}, bare, grey);

  MaterialDesc glow;
  glow.name = "emissive";
  glow.base_color = glm::dvec4(0.1, 0.1, 0.1, 1.0);
  glow.emissive = glm::dvec3(1.0, 0.75, 0.5);
  glow.emissive_strength = 4.0;
  const Geometry small = b.add_geometry(make_sphere(0.1f, 16, 8, {2, 1}, true));
  b.add_mesh_node("emissive_sphere", {1.2, 0.1, 0.6}, small, b.add_material(glow));

  // No glTF range: the seeds' lights fall off by inverse square alone (kit-bench's
  // small lights carry one, bench_renderer.h).
  b.add_point_light("warm_white", {-2.0, 2.0, 0.5}, {1.0, 0.85, 0.7}, 50.0);
  b.add_point_light("cool_blue", {2.0, 1.8, 0.5}, {0.55, 0.7, 1.0}, 40.0);
  b.add_point_light("reddish", {0.5, 2.4, 0.2}, {1.0, 0.35, 0.25}, 25.0);
  b.add_spot_light("spot", {0.0, 3.5, 6.0}, {0.0, 0.95, -1.0}, kWhite, 80.0, 0.25, 0.45);

  b.add_camera({0.0, 2.2, 6.5}, {0.0, 0.8, -1.0}, 0.8);
  return b;
}

GltfSceneWriter build_sphere_scene() {
  GltfSceneWriter b("sphere");
  const MaterialDesc mat = plain_material("terracotta", glm::dvec4(0.8, 0.3, 0.2, 1.0), 0.4);
  const Geometry sphere = b.add_geometry(make_sphere(1.0f, 64, 32, {2, 1}, true));
  b.add_mesh_node("sphere", {0, 0, 0}, sphere, b.add_material(mat));
  b.add_point_light("light", {2, 2, 3}, kWhite, 50.0);
  b.add_camera({0, 0, 4}, {0, 0, 0}, 0.7);
  return b;
}

GltfSceneWriter build_grazing_scene() {
  GltfSceneWriter b("grazing");
  const MaterialDesc mat = plain_material("white_glossy", glm::dvec4(1.0), 0.3);
  const Geometry plane =
      b.add_geometry(make_quad({1, 0, 0}, {0, 0, -1}, {20, 20}, {10, 10}, false));
  b.add_mesh_node("plane", {0, 0, 0}, plane, b.add_material(mat));
  b.add_point_light("light", {0, 0.02, -2}, kWhite, 30.0);
  b.add_camera({0, 0.05, 6}, {0, 0, -10}, 0.8);
  return b;
}

// A white, fully rough floor seen at grazing angles (n.v from about 0.05 to 0.3), for
// kit-grade's lab 6: there the diffuse part of the image-based light is as large as the
// reflection, and the BRDF table's diffuse Fresnel weight C is at its smallest (about
// 0.97), so an ibl.frag that leaves C out is 3 % too bright over the whole floor. Rough,
// so that no sharp reflection of the environment's sun makes the image driver-sensitive.
GltfSceneWriter build_matte_scene() {
  GltfSceneWriter b("matte");
  const MaterialDesc mat = plain_material("white_matte", glm::dvec4(0.9, 0.9, 0.9, 1.0), 1.0);
  const Geometry plane =
      b.add_geometry(make_quad({1, 0, 0}, {0, 0, -1}, {30, 30}, {1, 1}, false));
  b.add_mesh_node("floor", {0, 0, -10}, plane, b.add_material(mat));
  b.add_camera({0, 0.5, 4}, {0, -0.3, -6}, 0.6);
  return b;
}

// A spot light with a wide penumbra (inner cone 10 degrees, outer 45) over a plain
// floor, seen from above: the falloff between the cones covers much of the image,
// so interpolating over the angle instead of its cosine, or a linear ramp instead
// of the smoothstep, changes thousands of pixels (the default scene's spot has a
// penumbra of 14 to 26 degrees, too narrow to tell them apart). kit-grade's lab 3.
GltfSceneWriter build_spot_scene() {
  GltfSceneWriter b("spot");
  add_grey_floor(b, 0.7);
  // Aimed almost straight down (tilted 5.7 degrees: a look-at along -Y has no up).
  b.add_spot_light("spot", {0.0, 3.0, 0.3}, {0.0, 0.0, 0.0}, kWhite, 30.0, glm::radians(10.0),
                   glm::radians(45.0));
  b.add_camera({0.0, 5.0, 6.0}, {0.0, 0.0, 1.0}, 0.8);
  return b;
}

// A sphere on a floor lit by a low sun (a directional light 26 degrees above the
// horizon) and a point light. The sun's node stands high above the sphere, where
// a point light would light the floor almost head-on: a sun treated as a point
// light at its node, lit from +direction, or dimmed with distance (lab 3) changes
// most of the image, and the point light keeps the positional path graded too.
// kit-grade's labs 2 and 3.
const glm::dvec3 kSunDirection(1.0, -0.5, -0.3);  // where its light travels (normalised by the node)
const glm::dvec3 kSunNode(0.5, 4.0, 0.5);
GltfSceneWriter build_sun_scene() {
  GltfSceneWriter b("sun");
  add_grey_floor(b, 0.6);
  const MaterialDesc ball = plain_material("blue_ball", glm::dvec4(0.25, 0.45, 0.8, 1.0), 0.35);
  const Geometry sphere = b.add_geometry(make_sphere(1.0f, 64, 32, {2, 1}, true));
  b.add_mesh_node("sphere", {0, 1, 0}, sphere, b.add_material(ball));
  b.add_directional_light("sun", kSunNode, kSunDirection, {1.0, 0.9, 0.75}, 2.5);
  b.add_point_light("lamp", {-2.0, 1.5, 2.5}, {0.6, 0.75, 1.0}, 3.0);  // lab 2 has no falloff
  b.add_camera({0.0, 3.0, 7.0}, {0.0, 0.6, 0.0}, 0.8);
  return b;
}

// A close-up of one glossy highlight on a dark dielectric sphere (roughness 0.2):
// the highlight fills much of the view, so a mistake that changes only the
// specular peak (its height, width or clamping) changes thousands of pixels, where
// on the other scenes it covers a handful. kit-grade's lab 2.
GltfSceneWriter build_highlight_scene() {
  GltfSceneWriter b("highlight");
  const MaterialDesc mat = plain_material("glossy_red", glm::dvec4(0.5, 0.1, 0.1, 1.0), 0.2);
  const Geometry sphere = b.add_geometry(make_sphere(1.0f, 128, 64, {2, 1}, true));
  b.add_mesh_node("sphere", {0, 0, 0}, sphere, b.add_material(mat));
  const glm::dvec3 light(2.0, 2.0, 4.0), eye(0.0, 0.0, 3.5);
  b.add_point_light("light", light, kWhite, 1.5);  // lab 2 has no falloff: a peak of about 3
  // Aimed at the mirror point: where the normal halves the directions to the light and the eye.
  const glm::dvec3 mirror = glm::normalize(glm::normalize(light) + glm::normalize(eye));
  b.add_camera(eye, mirror, 0.2);
  return b;
}

GltfSceneWriter build_normal_map_scene(const Textures& tex) {
  GltfSceneWriter b("normalmap");
  const glm::vec3 x(1, 0, 0), y(0, 1, 0);
  const int grey =
      b.add_material(normal_mapped_grey(b.add_texture("brick_normal.png", tex.brick_normal)));

  // The quads span y in [-0.8, 1.2], so the sphere below (top at y = -0.8) stays clear.
  const Geometry quad = b.add_geometry(make_quad(x, y, {2, 2}, {1, 1}, false));
  b.add_mesh_node("quad", {-1.1, 0.2, 0}, quad, grey);
  const Geometry mirrored = b.add_geometry(make_quad(x, y, {2, 2}, {1, 1}, true));
  b.add_mesh_node("quad_mirrored", {1.1, 0.2, 0}, mirrored, grey);

  const Geometry sphere = b.add_geometry(make_sphere(0.6f, 32, 16, {2, 1}, false));
  b.add_mesh_node("sphere_no_tangents", {0, -1.4, 0}, sphere, grey);

  // A non-uniform scale only changes normals that are not aligned with its axes, so the
  // child tilts its quad 30 degrees upwards. Correct normal matrix (inverse transpose):
  // world normal ~(0, 0.756, 0.655); the plain model matrix would give ~(0, 0.277, 0.961).
  const int parent = b.add_node({"scaled_parent", {0, 1.6, 0}, kNoRotation, {2.0, 0.5, 1.0}});
  const Geometry strip = b.add_geometry(make_quad(x, y, {2, 1}, {1, 0.5}, false));
  const glm::dquat tilt = glm::angleAxis(glm::radians(-30.0), glm::dvec3(1, 0, 0));
  b.add_node({"tilted_quad", {0, 0, 0}, tilt, kUnitScale, b.add_mesh("tilted_quad", strip, grey)},
             parent);

  b.add_point_light("light", {0, 0, 2.5}, kWhite, 40.0);
  // From 6.05 m, not 6: at 6 the quads' lower edge fell 0.002 pixels from the centres of
  // row 122 of the grader's 256x192, and rasterisers snap such an edge either way (SwiftShader
  // drew the row, llvmpipe did not). Every straight edge now lies 0.08 pixels or more from a
  // row or column of centres.
  b.add_camera({0, 0, 6.05}, {0, 0, 0}, 0.9);
  return b;
}

// The normalmap scene's brick quads seen from 0.9 m, for kit-grade's lab 4: the normal
// map is magnified (about 2 pixels a texel), so every lookup reads level 0 through the
// magnification filter, which GL fixes up to precision. Where the map is minified (the
// normalmap scene), the mip levels' blend and the level of detail are the
// implementation's to approximate, and GPUs move the right answer there by 0.4 degrees
// on average (tools/grade/reference_store/references.h, the filter allowance): a mistake smaller than
// that, like a texel decoded as (255 t - 128) / 127, shows only here. The camera looks
// across the seam between the plain and the mirrored quad, turned 18 degrees off the
// quads' normal and rolled 20 degrees: it turns about all three axes, so a tangent frame
// built in another space (view space for the tangent, world space for the normal) is off
// here, where a camera that only pitches leaves the quads' x tangents alone. The light
// grazes from the left so the bevels' slopes show.
GltfSceneWriter build_closeup_scene(const Textures& tex) {
  GltfSceneWriter b("closeup");
  const glm::vec3 x(1, 0, 0), y(0, 1, 0);
  const int grey = b.add_material(normal_mapped_grey(b.add_texture("brick_normal.png", tex.brick_normal)));
  b.add_mesh_node("quad", {-1.0, 0.0, 0}, b.add_geometry(make_quad(x, y, {2, 2}, {1, 1}, false)), grey);
  b.add_mesh_node("quad_mirrored", {1.0, 0.0, 0}, b.add_geometry(make_quad(x, y, {2, 2}, {1, 1}, true)), grey);
  b.add_point_light("light", {-1.2, 0.4, 0.6}, kWhite, 3.0);
  b.add_camera({0.28, 0.1, 0.86}, {0.0, 0.0, 0.0}, 0.8, 20.0);
  return b;
}

// Each texture reference of a material read its own way, for kit-grade's labs 1 and 4:
//  * left, a quad with two UV sets (TEXCOORD_1 is TEXCOORD_0 turned a quarter and halved)
//    whose base colour reads UV set 0 and its metallic-roughness and emissive textures UV
//    set 1, each through a KHR_texture_transform of its own; the metallic-roughness
//    texture's three channels differ (make_packed_orm). A texture read at another's UV, at
//    UV set 0, without its transform, or from the wrong channel, shows;
//  * right, a quad with smooth bumps (make_bump_normal) at normalTexture.scale 0.4,
//    turned 35 degrees in its plane under a parent scaled (1.5, 0.8, 1): its tangent lies
//    along no axis of the scale, so a tangent taken to world space by the normal matrix
//    instead of the model matrix (which agree where the tangent lies along an axis: the
//    normalmap scene's quads) turns the bumps' slopes, and an ignored scale steepens them.
GltfSceneWriter build_texturing_scene() {
  GltfSceneWriter b("texturing");
  const glm::vec3 x(1, 0, 0), y(0, 1, 0);

  MaterialDesc uv_sets;
  uv_sets.name = "two_uv_sets";
  uv_sets.metallic = 1.0;   // the factors pass the texture's channels through
  uv_sets.roughness = 1.0;
  uv_sets.base_color_texture = b.add_texture("uv_grid.png", make_uv_grid());
  uv_sets.base_color_uv = {0, true, {0.1, 0.2}, 0.35, {1.5, 0.75}};
  uv_sets.metallic_roughness_texture = b.add_texture("packed_orm.png", make_packed_orm());
  uv_sets.metallic_roughness_uv = {1, true, {0.3, 0.0}, -0.6, {1.25, 2.0}};
  uv_sets.emissive = glm::dvec3(0.6, 0.5, 0.4);
  // The grid's cells differ from each other (no period inside the texture), so a texture
  // read at another's UV set or transform cannot land on texels that look the same.
  uv_sets.emissive_texture = uv_sets.base_color_texture;
  uv_sets.emissive_uv = {1, true, {0.5, 0.25}, 0.0, {2.0, 2.0}};
  MeshData quad = make_quad(x, y, {2.0f, 2.0f}, {1, 1}, false);
  for (const glm::vec2& uv0 : quad.uvs) quad.uvs1.emplace_back(0.5f * uv0.y + 0.25f, 1.0f - 0.5f * uv0.x);
  b.add_mesh_node("two_uv_sets_quad", {-1.3, 0.0, 0.0}, b.add_geometry(quad), b.add_material(uv_sets));

  MaterialDesc bumpy = normal_mapped_grey(b.add_texture("bumps_normal.png", make_bump_normal()));
  bumpy.name = "scaled_normal_map";
  bumpy.normal_scale = 0.4;
  bumpy.normal_uv = {0, true, {0.25, 0.1}, 0.0, {1.0, 1.0}};
  const int parent = b.add_node({"stretched_parent", {1.2, 0.0, 0.0}, kNoRotation, {1.5, 0.8, 1.0}});
  const glm::dquat turn = glm::angleAxis(glm::radians(35.0), glm::dvec3(0, 0, 1));
  const Geometry small_quad = b.add_geometry(make_quad(x, y, {1.3f, 1.3f}, {1, 1}, false));
  b.add_node({"turned_quad", {0, 0, 0}, turn, kUnitScale, b.add_mesh("turned_quad", small_quad, b.add_material(bumpy))},
             parent);

  b.add_point_light("front", {0.0, 0.5, 3.0}, kWhite, 20.0);
  b.add_point_light("side", {3.5, 0.0, 0.8}, {1.0, 0.9, 0.8}, 10.0);  // grazes the bevels
  b.add_camera({0.0, 0.0, 4.8}, {0.0, 0.0, 0.0}, 0.8);
  return b;
}

// Two lights whose glTF range ends inside the view, over a plain floor, for kit-grade's
// lab 3: a point light 0.5 m above the floor with range 2.5 and a spot light whose range
// (2.8) ends within its outer cone. The window 1 - (d / range)^4, squared, takes each to 0
// at its range and dims it by 12 % already half way, so a falloff that drops the window
// changes most of the lit floor (no light of the other scenes has a range).
GltfSceneWriter build_range_scene() {
  GltfSceneWriter b("range");
  add_grey_floor(b, 0.7);
  b.add_point_light("short_point", {-1.5, 0.5, 0.0}, {1.0, 0.85, 0.7}, 8.0, 2.5);
  b.add_spot_light("short_spot", {2.0, 2.0, -0.5}, {2.1, 0.0, -0.4}, {0.7, 0.8, 1.0}, 40.0, glm::radians(20.0),
                   glm::radians(40.0), 2.8);
  b.add_camera({0.0, 5.0, 6.0}, {0.0, 0.0, 0.5}, 0.8);
  return b;
}

// A point and a spot light without a range (glTF's default: unlimited), for kit-grade's
// lab 7: their volumes reach the framework's cut-off (light_volumes.h, volume_radius), and
// a volume scaled by the glTF range, 0 for them, draws nothing. No other grading scene has
// such a light, so that mistake kept full marks, and the default scene's light vanished.
GltfSceneWriter build_unranged_scene() {
  GltfSceneWriter b("unranged");
  add_grey_floor(b, 0.6);
  const MaterialDesc red = plain_material("red", glm::dvec4(0.8, 0.25, 0.2, 1.0), 0.4);
  b.add_mesh_node("ball", {-0.8, 0.5, 0.0}, b.add_geometry(make_sphere(0.5f, 48, 24, {1, 1}, false)), b.add_material(red));
  b.add_point_light("unranged_point", {-1.6, 1.2, 1.0}, {1.0, 0.9, 0.8}, 3.0);
  b.add_spot_light("unranged_spot", {1.5, 2.5, 0.5}, {1.2, 0.0, -0.5}, {0.7, 0.8, 1.0}, 30.0, glm::radians(15.0),
                   glm::radians(30.0));
  b.add_camera({0.0, 3.0, 5.0}, {0.0, 0.3, 0.0}, 0.8);
  return b;
}

// Many small lights, for kit-grade's lab 7 (light volumes): 128 coloured point lights of
// 0.08 cd, 0.15 to 0.4 m above a 12 x 12 m floor among five spheres, each with a glTF range
// of 0.9 m (so its volume is exact: lights.glsl kit_range_window), a dim directional light
// and an emissive sphere (both stay in the full-screen pass). Every light lights a patch of
// floor a few hundred pixels wide: the full-screen loop shades each pixel for all 128, the
// volumes for the few that reach it.
GltfSceneWriter build_lights_scene() {
  GltfSceneWriter b("lights");
  add_grey_floor(b, 0.6);
  const Geometry ball = b.add_geometry(make_sphere(0.5f, 48, 24, {1, 1}, false));
  const glm::dvec3 balls[5] = {{-2.5, 0.5, -1.5}, {0.0, 0.5, -2.5}, {2.5, 0.5, -1.0}, {-1.2, 0.5, 1.2}, {1.6, 0.5, 1.8}};
  for (int i = 0; i < 5; ++i) {
    const double roughness = 0.25 + 0.15 * i, metallic = i % 2 == 0 ? 0.0 : 1.0;
    const MaterialDesc m = plain_material("ball_" + std::to_string(i), glm::dvec4(0.8, 0.75 - 0.1 * i, 0.5 + 0.1 * i, 1.0),
                                          roughness, metallic);
    b.add_mesh_node("ball_" + std::to_string(i), balls[i], ball, b.add_material(m));
  }
  MaterialDesc glow = plain_material("glow", glm::dvec4(0.0, 0.0, 0.0, 1.0), 0.5);
  glow.emissive = glm::dvec3(1.0, 0.6, 0.2);
  b.add_mesh_node("emitter", {0.0, 0.25, 0.3}, b.add_geometry(make_sphere(0.25f, 32, 16, {1, 1}, false)), b.add_material(glow));
  b.add_directional_light("moon", {0.0, 5.0, 0.0}, glm::normalize(glm::dvec3(0.3, -1.0, -0.4)), {0.6, 0.7, 1.0}, 0.15);
  // A jittered 16 x 8 grid over the floor: deterministic, no two lights on one spot.
  constexpr int kColumns = 16, kRows = 8;
  for (int i = 0; i < kColumns * kRows; ++i) {
    const int col = i % kColumns, row = i / kColumns;
    const double jx = std::fmod(0.618034 * (i + 1), 1.0) - 0.5, jz = std::fmod(0.754878 * (i + 1), 1.0) - 0.5;
    const glm::dvec3 at(-5.4 + (col + 0.5 + 0.6 * jx) * (10.8 / kColumns), 0.15 + 0.25 * std::fmod(0.5698 * i, 1.0),
                        -4.0 + (row + 0.5 + 0.6 * jz) * (8.0 / kRows));
    const double hue = 6.2831853 * i / (kColumns * kRows);
    const glm::dvec3 colour(0.6 + 0.4 * std::cos(hue), 0.6 + 0.4 * std::cos(hue + 2.094), 0.6 + 0.4 * std::cos(hue + 4.189));
    b.add_point_light("small_" + std::to_string(i), at, colour, 0.08, 0.9);
  }
  b.add_camera({0.0, 5.5, 7.0}, {0.0, 0.0, -0.5}, 0.8);
  return b;
}

// The camera inside a light's volume, for kit-grade's lab 7: a point light with a 4 m range
// 2 m in front of the camera, over a floor before a wall, and a second light with a short
// range (1.2 m) to the right, seen from outside. A volume drawn with its front faces only
// leaves the first light out: its front faces are behind the camera.
GltfSceneWriter build_inside_scene() {
  GltfSceneWriter b("inside");
  add_grey_floor(b, 0.5);
  const MaterialDesc wall = plain_material("wall", glm::dvec4(0.7, 0.65, 0.6, 1.0), 0.8);
  b.add_mesh_node("wall", {0.0, 2.0, -2.0}, b.add_geometry(make_quad({1, 0, 0}, {0, 1, 0}, {12, 4}, {1, 1}, false)),
                  b.add_material(wall));
  const MaterialDesc blue = plain_material("blue", glm::dvec4(0.2, 0.35, 0.8, 1.0), 0.35);
  b.add_mesh_node("ball", {-0.6, 0.45, -0.6}, b.add_geometry(make_sphere(0.45f, 48, 24, {1, 1}, false)), b.add_material(blue));
  b.add_point_light("around_camera", {0.0, 1.3, 1.2}, {1.0, 0.9, 0.8}, 2.0, 4.0);
  b.add_point_light("short", {1.6, 0.4, -1.2}, {0.6, 0.8, 1.0}, 1.5, 1.2);
  b.add_camera({0.2, 1.6, 3.0}, {0.0, 0.8, -1.5}, 0.9);
  return b;
}

// glTF material features beyond the metallic-roughness factors, one object each, for
// kit-grade's labs 1 and 2 and the G-buffer tests:
//  * a sphere with a black base colour and a red emissive colour times a checker
//    emissive texture: its light is the emissive colour alone (an emission
//    multiplied by the albedo, or reduced to one scalar, or missing the texture, shows);
//  * a MASK quad whose base colour alpha ramps from 0 (left) to 1 (right), cutoff 0.3:
//    its left 30 % is no surface at all;
//  * a double-sided quad turned away from the camera: drawn only without back-face
//    culling, and lit only with its normal flipped towards the viewer;
//  * a BLEND strip with base colour alpha 0.5 across the lower edge of the three: in
//    stage 1's G-buffer with albedo.a 0.5, from stage 2 laid over them by the forward pass.
//  * two vertex-coloured strips above the rest (COLOR_0 multiplies the base colour): a
//    FLOAT VEC3 ramp from orange to blue, and a MASK strip of normalized UNSIGNED_BYTE
//    VEC4 whose alpha ramps from 64/255 to 1 under cutoff 0.5, so its left third is no
//    surface (a geometry pass that ignores COLOR_0, or its alpha, shows).
GltfSceneWriter build_materials_scene(const Textures& tex) {
  GltfSceneWriter b("materials");
  const glm::vec3 x(1, 0, 0), y(0, 1, 0);

  MaterialDesc glow;
  glow.name = "red_emitter_black_base";
  glow.base_color = glm::dvec4(0.0, 0.0, 0.0, 1.0);
  glow.roughness = 0.5;
  glow.emissive = glm::dvec3(1.0, 0.15, 0.05);
  glow.emissive_strength = 3.0;
  glow.emissive_texture = b.add_texture("checker.png", tex.checker);
  const Geometry sphere = b.add_geometry(make_sphere(0.6f, 24, 12, {2, 1}, true));
  b.add_mesh_node("emissive_sphere", {-1.6, 0.5, 0.0}, sphere, b.add_material(glow));

  MaterialDesc masked;
  masked.name = "masked_ramp";
  masked.base_color = glm::dvec4(0.3, 0.7, 1.0, 1.0);
  masked.roughness = 0.4;
  masked.base_color_texture = b.add_texture("alpha_ramp.png", make_alpha_ramp_checker());
  masked.alpha_mode = "MASK";
  masked.alpha_cutoff = 0.3;
  const Geometry quad = b.add_geometry(make_quad(x, y, {1.4f, 1.4f}, {1, 1}, false));
  b.add_mesh_node("masked_quad", {0.0, 0.5, 0.0}, quad, b.add_material(masked));

  MaterialDesc two_sided;
  two_sided.name = "double_sided_yellow";
  two_sided.base_color = glm::dvec4(0.8, 0.7, 0.2, 1.0);
  two_sided.roughness = 0.6;
  two_sided.double_sided = true;
  // Front face along -z (away from the camera), then turned 25 degrees about y.
  const Geometry back = b.add_geometry(make_quad(-x, y, {1.2f, 1.4f}, {1, 1}, false));
  const glm::dquat turn = glm::angleAxis(glm::radians(25.0), glm::dvec3(0, 1, 0));
  b.add_node({"double_sided_quad", {1.6, 0.5, 0.0}, turn, kUnitScale,
              b.add_mesh("double_sided_quad", back, b.add_material(two_sided))});

  MaterialDesc blend;
  blend.name = "blend_half";
  blend.base_color = glm::dvec4(0.9, 0.4, 0.3, 0.5);
  blend.roughness = 0.7;
  blend.alpha_mode = "BLEND";
  const Geometry strip = b.add_geometry(make_quad(x, y, {4.0f, 0.4f}, {1, 1}, false));
  // In front of the lower edge of the sphere and both quads, so the forward pass blends it over them.
  b.add_mesh_node("blend_strip", {0.0, -0.05, 0.3}, strip, b.add_material(blend));

  // make_quad's corners: bottom-left, bottom-right, top-right, top-left.
  const MaterialDesc tinted = plain_material("vertex_coloured", glm::dvec4(0.9, 0.8, 0.7, 1.0), 0.5);
  Geometry ramp = b.add_geometry(make_quad(x, y, {3.0f, 0.3f}, {1, 1}, false));
  const glm::vec3 orange(1.0f, 0.45f, 0.1f), blue(0.1f, 0.35f, 1.0f);
  b.add_colors(ramp, std::vector<glm::vec3>{orange, blue, blue, orange});
  b.add_mesh_node("vertex_colour_strip", {0.0, 1.45, 0.0}, ramp, b.add_material(tinted));

  MaterialDesc tinted_mask = tinted;
  tinted_mask.name = "vertex_coloured_mask";
  tinted_mask.alpha_mode = "MASK";
  Geometry faded = b.add_geometry(make_quad(x, y, {3.0f, 0.3f}, {1, 1}, false));
  const glm::u8vec4 green_faint(40, 200, 90, 64), magenta_opaque(220, 30, 160, 255);
  b.add_colors(faded, std::vector<glm::u8vec4>{green_faint, magenta_opaque, magenta_opaque, green_faint});
  b.add_mesh_node("vertex_alpha_strip", {0.0, 1.8, 0.0}, faded, b.add_material(tinted_mask));

  b.add_point_light("light", {0.5, 2.0, 4.0}, kWhite, 3.0);  // lab 2 has no falloff
  b.add_camera({0.0, 0.6, 5.0}, {0.0, 0.3, 0.0}, 0.75);
  return b;
}

// ---------------------------------------------------------------------------
// The heavy scene: load time and memory of a model as large as students bring
// (`kit-scenes --heavy OUT_DIR`; not part of the build's scenes, since its PNGs
// take about 30 MB and several seconds to write).
constexpr int kHeavySpheresPerSide = 4;     // 16 spheres
constexpr int kHeavySphereSegments = 256;   // 256 x 128 quads: 65,536 triangles a sphere, 1,048,576 in all
constexpr int kHeavySphereRings = 128;
constexpr int kHeavyTextureSize = 2048;     // one base colour texture a sphere
constexpr int kHeavyUnusedImages = 4;       // listed by the file, used by no material

// Smooth bands of a per-texture hue: distinct textures that PNG compresses well.
Image8 make_heavy_texture(int index) {
  Image8 img(kHeavyTextureSize, kHeavyTextureSize, 3);
  const glm::vec3 hue(0.5f + 0.5f * hash01(std::uint32_t(index) * 3u), 0.5f + 0.5f * hash01(std::uint32_t(index) * 3u + 1u),
                      0.5f + 0.5f * hash01(std::uint32_t(index) * 3u + 2u));
  for (int y = 0; y < img.height; ++y) {
    const float band = 0.75f + 0.25f * float(std::sin(2.0 * kPi * 8.0 * y / img.height));
    for (int x = 0; x < img.width; ++x) img.set(x, y, hue * band);
  }
  return img;
}

GltfSceneWriter build_heavy_scene() {
  GltfSceneWriter b("heavy");
  const MeshData sphere_mesh = make_sphere(0.45f, kHeavySphereSegments, kHeavySphereRings, {1, 1}, false);
  for (int i = 0; i < kHeavySpheresPerSide * kHeavySpheresPerSide; ++i) {
    const Geometry sphere = b.add_geometry(sphere_mesh);  // a buffer of its own, as separate models have
    MaterialDesc mat;
    mat.name = "heavy_" + std::to_string(i);
    mat.roughness = 0.5;
    mat.base_color_texture = b.add_texture(mat.name + ".png", make_heavy_texture(i));
    const glm::dvec3 at(i % kHeavySpheresPerSide - 1.5, i / kHeavySpheresPerSide - 1.5, 0.0);
    b.add_mesh_node(mat.name, at, sphere, b.add_material(mat));
  }
  for (int i = 0; i < kHeavyUnusedImages; ++i)
    b.add_image("unused_" + std::to_string(i) + ".png", make_heavy_texture(100 + i));
  b.add_point_light("light", {0, 0, 4}, kWhite, 60.0);
  b.add_camera({0, 0, 7}, {0, 0, 0}, 0.8);
  return b;
}

// ---------------------------------------------------------------------------
// The crowd scene: the lighting pass's benchmark (kit-bench's `crowd` configuration,
// issue 13), laid out like a well-known deferred-shading tutorial program's scene:
// nine instances of one 19k-triangle model on a 3 x 3 grid, 32 coloured point lights
// scattered among them, no floor, at 800 x 600 (the camera is raised so all nine show).
constexpr int kCrowdModelSegments = 128;  // 128 x 76 quads, less the poles' halves: 19,200 triangles
constexpr int kCrowdModelRings = 76;
constexpr int kCrowdGridSide = 3;         // 9 instances, 172,800 triangles
constexpr double kCrowdSpacing = 3.0;     // metres between instances
constexpr int kCrowdLights = 32;
constexpr double kCrowdLightCandela = 1.5;  // each light: the 32 together expose like the default scene

GltfSceneWriter build_crowd_scene() {
  GltfSceneWriter b("crowd");
  const MaterialDesc mat = plain_material("crowd_model", glm::dvec4(0.7, 0.62, 0.55, 1.0), 0.45);
  const Geometry model = b.add_geometry(make_sphere(0.8f, kCrowdModelSegments, kCrowdModelRings, {4, 2}, false));
  const int material = b.add_material(mat);
  const double half = 0.5 * (kCrowdGridSide - 1);
  for (int i = 0; i < kCrowdGridSide * kCrowdGridSide; ++i) {
    const glm::dvec3 at(kCrowdSpacing * (i % kCrowdGridSide - half), -0.5, kCrowdSpacing * (i / kCrowdGridSide - half));
    b.add_mesh_node("crowd_" + std::to_string(i), at, model, material);
  }
  // Deterministic scatter over x, z in [-3.5, 3.5] and y in [-1.5, 2.5] (the tutorial's
  // program: y in [-4, 2], which lights its models mostly from below), colours in [0.5, 1].
  for (int i = 0; i < kCrowdLights; ++i) {
    const auto r = [i](std::uint32_t k) { return double(hash01(std::uint32_t(i) * 8u + k + 5000u)); };
    const glm::dvec3 position(7.0 * r(0) - 3.5, 4.0 * r(1) - 1.5, 7.0 * r(2) - 3.5);
    const glm::dvec3 color(0.5 + 0.5 * r(3), 0.5 + 0.5 * r(4), 0.5 + 0.5 * r(5));
    b.add_point_light("light_" + std::to_string(i), position, color, kCrowdLightCandela);
  }
  b.add_camera({0.0, 3.5, 8.0}, {0.0, -0.5, 0.0}, glm::radians(45.0));
  return b;
}


// "obj-cube": an OBJ/MTL scene, as students bring them (obj_scene.h): a unit cube
// whose faces share one brick material, in Phong terms (Kd, Ks, Ns) with colour and
// normal maps, and no lights, so the tools light it with the default rig.
//   ./kit render --stage normalmap --scene build/default/scenes/obj-cube/obj-cube.obj --out cube.png
void write_obj_cube_scene(const fs::path& out_dir, const Textures& tex) {
  const fs::path dir = out_dir / "obj-cube";
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) throw std::runtime_error("cannot create " + dir.string() + ": " + ec.message());
  write_png(dir / "brick_color.png", tex.brick_color);
  write_png(dir / "brick_normal.png", tex.brick_normal);
  std::string obj = "# kit-scenes: a unit cube for the OBJ loader\nmtllib obj-cube.mtl\no cube\n";
  for (int corner = 0; corner < 8; ++corner)
    obj += std::string("v ") + ((corner & 1) ? "0.5" : "-0.5") + ((corner & 2) ? " 0.5" : " -0.5") +
           ((corner & 4) ? " 0.5" : " -0.5") + "\n";
  obj += "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n";
  obj += "vn 1 0 0\nvn -1 0 0\nvn 0 1 0\nvn 0 -1 0\nvn 0 0 1\nvn 0 0 -1\n";
  // Each face: its corners (1 + x + 2y + 4z, 1-based) counter-clockwise seen from
  // outside from the bottom left (UVs 0,0 1,0 1,1 0,1), then its normal's index.
  const int faces[6][5] = {{6, 2, 4, 8, 1}, {1, 5, 7, 3, 2}, {7, 8, 4, 3, 3},
                           {1, 2, 6, 5, 4}, {5, 6, 8, 7, 5}, {2, 1, 3, 4, 6}};
  obj += "usemtl brick\n";
  for (const auto& f : faces) {
    obj += "f";
    for (int k = 0; k < 4; ++k) obj += " " + std::to_string(f[k]) + "/" + std::to_string(k + 1) + "/" + std::to_string(f[4]);
    obj += "\n";
  }
  const std::string mtl =
      "# Phong terms: the kit turns Ns into roughness and Ks against Kd into metallic\n"
      "newmtl brick\nKd 1 1 1\nKs 0.3 0.3 0.3\nNs 40\nmap_Kd brick_color.png\nmap_Bump brick_normal.png\n";
  for (const auto& [name, text] : {std::pair<const char*, const std::string&>{"obj-cube.obj", obj}, {"obj-cube.mtl", mtl}}) {
    std::ofstream out(dir / name, std::ios::binary);
    out << text;
    if (!out) throw std::runtime_error("cannot write " + (dir / name).string());
  }
}

}  // namespace

void write_kit_scenes(const fs::path& out_dir) {
  const Textures textures;
  build_default_scene(textures).write(out_dir);
  build_sphere_scene().write(out_dir);
  build_grazing_scene().write(out_dir);
  build_normal_map_scene(textures).write(out_dir);
  build_spot_scene().write(out_dir);
  build_highlight_scene().write(out_dir);
  build_sun_scene().write(out_dir);
  build_materials_scene(textures).write(out_dir);
  build_texturing_scene().write(out_dir);
  build_closeup_scene(textures).write(out_dir);
  build_lights_scene().write(out_dir);
  build_inside_scene().write(out_dir);
  build_unranged_scene().write(out_dir);
  build_range_scene().write(out_dir);
  build_matte_scene().write(out_dir);
  build_crowd_scene().write(out_dir);
  write_obj_cube_scene(out_dir, textures);
  write_studio_environment(out_dir / "environments" / "studio.exr");
  write_sun_environment(out_dir / "environments" / "sun.exr");
}

void write_heavy_scene(const fs::path& out_dir) { build_heavy_scene().write(out_dir); }

}  // namespace kit_scenes
