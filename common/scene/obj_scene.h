#pragma once
// Wavefront OBJ scenes with their MTL materials, read by tinyobjloader into the
// same kit::Scene the glTF loader fills (scene.h); load_scene hands .obj files here.
//
// What an OBJ becomes:
//  - faces triangulated; one Primitive per object ('o'/'g') and material, drawn once
//    with the identity transform; no lights and no camera (the tools frame the
//    bounds and light a scene without lights with the default rig, renderer.h);
//  - UVs flipped (v_kit = 1 - v_obj): OBJ's v grows up the image, the kit's (glTF's)
//    grows down it; faces without vn get flat normals (use_flat_normals), tangents
//    come from generate_tangents;
//  - materials from the MTL as material_from_mtl (obj_scene.cpp) documents: Kd and
//    map_Kd (sRGB) the base colour, d or Tr its alpha, Ke and map_Ke the emission,
//    norm or map_Bump/bump a tangent-space normal map (-bm its scale), Pr/Pm
//    when given, else roughness from Ns and metallic from Ks and Kd.
//
// Files named by the OBJ (mtllib, texture maps) must lie in the OBJ's folder or
// below it, as glTF URIs must (safe_file.h). Refused paths and malformed data throw
// kit::Error naming the file, the element and the reason; a missing MTL or texture,
// or a texture that is not PNG/JPEG, is a warning in Scene::warnings and is left out.
#include <string>

#include "scene/scene.h"

namespace kit {

// Whether `path` names an OBJ file: it ends in ".obj", in any case.
bool is_obj_path(const std::string& path);

// Whether this build reads OBJ files (libtinyobjloader-dev was found when it was configured).
bool obj_scenes_supported();

// Loads an OBJ file and the MTL files it names. Throws kit::Error (see above); in a
// build without OBJ support, always, saying which package to install.
Scene load_obj_scene(const std::string& path);

}  // namespace kit
