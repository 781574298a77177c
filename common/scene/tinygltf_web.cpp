// The browser build's tinygltf (KIT_WEB): the desktop links Debian's libtinygltf.so,
// which has no WebAssembly build, so its packaged header's implementation is compiled
// here. Images are decoded by the kit itself (gltf_loader.cpp's image hook,
// images/image_codecs_web.cpp), never by tinygltf's stb_image: this file compiles without
// it and defines the default loading callback the header's TinyGLTF constructor names as a
// refusal. The writing callback is tinygltf's own, with libstb-dev's stb_image_write: its
// signature changed between Debian 12's tinygltf and Debian 13's (URI callbacks), and the
// kit writes no glTF in the browser.
#define TINYGLTF_IMPLEMENTATION
#define TINYGLTF_NO_STB_IMAGE
#define TINYGLTF_NO_INCLUDE_STB_IMAGE_WRITE
#define STB_IMAGE_WRITE_IMPLEMENTATION
#define STB_IMAGE_WRITE_STATIC
#include <stb/stb_image_write.h>
#include <tiny_gltf.h>

namespace tinygltf {

bool LoadImageData(Image*, const int, std::string* err, std::string*, int, int, const unsigned char*, int, void*) {
  if (err) *err += "tinygltf's own image decoding is not in the browser build (the kit decodes images itself)\n";
  return false;
}

}  // namespace tinygltf
