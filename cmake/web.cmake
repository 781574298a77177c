# The browser build (KIT_WEB, included from CMakeLists.txt): kitcore compiled by emscripten
# for WebGL2 (OpenGL ES 3.0) from the same sources as the desktop's, and kit-web, the
# page's program (tools/web/). ./kit web configures it with emcmake and writes the site.
if(NOT EMSCRIPTEN)
  message(FATAL_ERROR "KIT_WEB needs emscripten's toolchain: emcmake cmake --preset web (./kit web does)")
endif()
set(KIT_BUILD_VIEWER OFF)
set(KIT_BUILD_TESTS OFF)
set(KIT_HAS_OSMESA OFF)
set(KIT_HAS_OBJ ON)
set(KIT_HAS_DRACO OFF)

# The header-only packages (libglm-dev, nlohmann-json3-dev, libstb-dev, libtinygltf-dev,
# and libtinyobjloader-dev's header, whose library the desktop links), each through a link
# of its own in the build: /usr/include as a whole would put the host's C library headers
# ahead of emscripten's. tinygltf's and tinyobjloader's implementations are compiled in
# common/scene/*_web.cpp.
set(KIT_WEB_INCLUDE ${CMAKE_BINARY_DIR}/web-include)
file(MAKE_DIRECTORY ${KIT_WEB_INCLUDE})
foreach(entry glm nlohmann stb tiny_gltf.h tiny_obj_loader.h)
  if(NOT EXISTS /usr/include/${entry})
    message(FATAL_ERROR "the browser build needs /usr/include/${entry}: install libglm-dev nlohmann-json3-dev "
                        "libstb-dev libtinygltf-dev libtinyobjloader-dev (./kit setup does)")
  endif()
  file(CREATE_LINK /usr/include/${entry} ${KIT_WEB_INCLUDE}/${entry} SYMBOLIC)
endforeach()
add_library(kit_web_headers INTERFACE)
target_include_directories(kit_web_headers SYSTEM INTERFACE ${KIT_WEB_INCLUDE})
# glm's own definitions, as its CMake package sets them on the desktop (none needed here).
add_library(glm::glm ALIAS kit_web_headers)

# Debian's emscripten runs its JavaScript optimiser (at every link) with the node of its
# config (/usr/share/emscripten/.emscripten: /usr/bin/node) and Debian's node-acorn,
# installed under /usr/share/nodejs, where Debian's nodejs looks by itself but a nodejs
# from elsewhere (NodeSource's 20.x, say) does not: "Cannot find module 'acorn'". The
# links are run with that folder on NODE_PATH.
set(kit_node_path /usr/share/nodejs)
if(NOT "$ENV{NODE_PATH}" STREQUAL "")
  string(APPEND kit_node_path ":$ENV{NODE_PATH}")
endif()
# The compilers' huge-page malloc (CMakeLists.txt) for the link's wasm-ld and optimisers too.
set(CMAKE_CXX_LINKER_LAUNCHER env "NODE_PATH=${kit_node_path}" ${kit_compiler_malloc})

# The kit reports every problem as a thrown kit::Error; emscripten's default catches no
# exception at all (an abort), so every file compiles and links with its exceptions.
add_compile_options(-fexceptions)
add_link_options(-fexceptions)

# The scenes and environments kit-scenes wrote in a desktop build: the browser build has
# no kit-scenes of its own (OpenImageIO writes its images). ./kit web builds them first.
set(KIT_WEB_SCENES ${PROJECT_SOURCE_DIR}/build/default/scenes CACHE PATH
    "The desktop build's generated scenes, packed into the site")
if(NOT EXISTS ${KIT_WEB_SCENES}/default/default.gltf)
  message(FATAL_ERROR "no scenes in ${KIT_WEB_SCENES}: build them first with `cmake --preset default && cmake --build "
                      "build/default --target kit_scene_files` (./kit web does), or set KIT_WEB_SCENES")
endif()

add_subdirectory(common)
add_subdirectory(tools/web)
message(STATUS "kit: browser build (emscripten ${EMSCRIPTEN_VERSION}); scenes from ${KIT_WEB_SCENES}; "
               "left out: Draco, meshoptimizer, OpenEXR, OpenImageIO, libpng (stb_image decodes PNG, JPEG, .hdr)")
