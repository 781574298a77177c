// The browser build's tinyobjloader (KIT_WEB): the desktop links Debian's
// libtinyobjloader.so, which has no WebAssembly build, so the implementation in the
// package's header (libtinyobjloader-dev's tiny_obj_loader.h, the one the desktop's library
// is built from) is compiled here, with the library's own settings (float reals, as
// tinyobjloader.pc has no TINYOBJLOADER_USE_DOUBLE). obj_scene.cpp is then the same
// loader as the desktop's.
#define TINYOBJLOADER_IMPLEMENTATION
#include <tiny_obj_loader.h>
