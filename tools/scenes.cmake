# kit-scenes: generates the kit's glTF test scenes. Included from tools/CMakeLists.txt;
# needs kit_warnings, kit_sanitizers, TinyGLTF::TinyGLTF, PkgConfig::OIIO and glm::glm from the
# top-level CMakeLists.txt. The fuzz build leaves it out: its harnesses read the
# scenes of the default build (instructor/fuzz/run_fuzz.sh --scenes).
if(KIT_FUZZ)
  return()
endif()
add_executable(kit-scenes ${CMAKE_CURRENT_LIST_DIR}/kit_scenes.cpp
  ${CMAKE_CURRENT_LIST_DIR}/scenes/scene_catalogue.cpp
  ${CMAKE_CURRENT_LIST_DIR}/scenes/gltf_scene_writer.cpp
  ${CMAKE_CURRENT_LIST_DIR}/scenes/scene_images.cpp
  ${CMAKE_CURRENT_LIST_DIR}/scenes/scene_meshes.cpp
  ${CMAKE_CURRENT_LIST_DIR}/scenes/environments.cpp)
# PkgConfig::OIIO: the top level finds OpenImageIO through pkg-config (see CMakeLists.txt).
target_link_libraries(kit-scenes PRIVATE kit_warnings kit_sanitizers TinyGLTF::TinyGLTF PkgConfig::OIIO glm::glm)

# The scenes are build outputs in ${CMAKE_BINARY_DIR}/scenes/<name>/, regenerated whenever
# kit-scenes changes. One command writes all twelve glTF scenes, the OBJ cube and lab 6's two
# environments (environments/studio.exr, sun.exr); the .gltf files stand for the rest.
set(KIT_SCENES_DIR ${CMAKE_BINARY_DIR}/scenes)
set(KIT_SCENE_FILES
  ${KIT_SCENES_DIR}/default/default.gltf
  ${KIT_SCENES_DIR}/sphere/sphere.gltf
  ${KIT_SCENES_DIR}/grazing/grazing.gltf
  ${KIT_SCENES_DIR}/normalmap/normalmap.gltf
  ${KIT_SCENES_DIR}/spot/spot.gltf
  ${KIT_SCENES_DIR}/highlight/highlight.gltf
  ${KIT_SCENES_DIR}/materials/materials.gltf
  ${KIT_SCENES_DIR}/sun/sun.gltf
  ${KIT_SCENES_DIR}/texturing/texturing.gltf
  ${KIT_SCENES_DIR}/closeup/closeup.gltf
  ${KIT_SCENES_DIR}/lights/lights.gltf
  ${KIT_SCENES_DIR}/inside/inside.gltf
  ${KIT_SCENES_DIR}/range/range.gltf
  ${KIT_SCENES_DIR}/matte/matte.gltf
  ${KIT_SCENES_DIR}/crowd/crowd.gltf)
set(KIT_SCENE_BYPRODUCTS
  ${KIT_SCENES_DIR}/default/default.bin
  ${KIT_SCENES_DIR}/default/checker.png
  ${KIT_SCENES_DIR}/default/brick_color.png
  ${KIT_SCENES_DIR}/default/brick_normal.png
  ${KIT_SCENES_DIR}/sphere/sphere.bin
  ${KIT_SCENES_DIR}/grazing/grazing.bin
  ${KIT_SCENES_DIR}/normalmap/normalmap.bin
  ${KIT_SCENES_DIR}/normalmap/brick_normal.png
  ${KIT_SCENES_DIR}/spot/spot.bin
  ${KIT_SCENES_DIR}/highlight/highlight.bin
  ${KIT_SCENES_DIR}/materials/materials.bin
  ${KIT_SCENES_DIR}/materials/checker.png
  ${KIT_SCENES_DIR}/materials/alpha_ramp.png
  ${KIT_SCENES_DIR}/sun/sun.bin
  ${KIT_SCENES_DIR}/texturing/texturing.bin
  ${KIT_SCENES_DIR}/texturing/uv_grid.png
  ${KIT_SCENES_DIR}/texturing/packed_orm.png
  ${KIT_SCENES_DIR}/texturing/bumps_normal.png
  ${KIT_SCENES_DIR}/closeup/closeup.bin
  ${KIT_SCENES_DIR}/lights/lights.bin
  ${KIT_SCENES_DIR}/inside/inside.bin
  ${KIT_SCENES_DIR}/closeup/brick_normal.png
  ${KIT_SCENES_DIR}/range/range.bin
  ${KIT_SCENES_DIR}/matte/matte.bin
  ${KIT_SCENES_DIR}/crowd/crowd.bin
  ${KIT_SCENES_DIR}/obj-cube/obj-cube.obj
  ${KIT_SCENES_DIR}/obj-cube/obj-cube.mtl
  ${KIT_SCENES_DIR}/obj-cube/brick_color.png
  ${KIT_SCENES_DIR}/obj-cube/brick_normal.png
  ${KIT_SCENES_DIR}/environments/studio.exr
  ${KIT_SCENES_DIR}/environments/sun.exr)
add_custom_command(
  OUTPUT ${KIT_SCENE_FILES}
  BYPRODUCTS ${KIT_SCENE_BYPRODUCTS}
  COMMAND kit-scenes ${KIT_SCENES_DIR}
  DEPENDS kit-scenes
  COMMENT "Generating glTF scenes in ${KIT_SCENES_DIR}"
  VERBATIM)
add_custom_target(kit_scene_files ALL DEPENDS ${KIT_SCENE_FILES})
