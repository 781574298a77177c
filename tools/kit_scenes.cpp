// kit-scenes: writes the kit's own glTF 2.0 test scenes.
//
//   kit-scenes OUT_DIR   ->  OUT_DIR/<name>/<name>.gltf + <name>.bin + *.png
//
// Everything is procedural and deterministic (no clocks, no random engines, only
// ordered containers), so the files are byte-identical on every run.
//
// Conventions the renderer relies on:
//  * right-handed, +Y up, metres; indexed (UNSIGNED_INT) triangle lists, CCW front faces;
//  * TEXCOORD_0 follows glTF: v = 0 is the top row of the image;
//  * TANGENT.w as tools/scenes/scene_meshes.h says (OpenGL's normal-map convention, glTF's).
//
// Its parts, in tools/scenes/: the scenes themselves (scene_catalogue.cpp), the glTF
// writer (gltf_scene_writer.h), textures (scene_images.h), meshes (scene_meshes.h) and
// lab 6's environments (environments.h).
#include <exception>
#include <filesystem>
#include <iostream>
#include <string>

#include "scenes/scene_catalogue.h"

int main(int argc, char** argv) {
  const bool heavy = argc == 3 && std::string(argv[1]) == "--heavy";
  if (argc != 2 && !heavy) {
    std::cerr << "usage: kit-scenes OUT_DIR          the kit's test scenes\n"
                 "       kit-scenes --heavy OUT_DIR  OUT_DIR/heavy: 1,048,576 triangles, 16 textures of 2048x2048\n";
    return 2;
  }
  try {
    const std::filesystem::path out_dir = argv[argc - 1];
    if (heavy)
      kit_scenes::write_heavy_scene(out_dir);
    else
      kit_scenes::write_kit_scenes(out_dir);
  } catch (const std::exception& e) {
    std::cerr << "kit-scenes: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
