// The browser build's tinygltf (KIT_WEB): the desktop links Debian's libtinygltf.so,
// which has no WebAssembly build, so its packaged header's implementation is compiled
// here. Images are decoded by the kit itself (gltf_loader.cpp's image hook,
// images/image_codecs_web.cpp), never by tinygltf's stb_image, and nothing is written:
// this file compiles without tinygltf's stb code and defines the two default callbacks
// that the header's TinyGLTF constructor names (as the other files include it, with
// them) as refusals.
#define TINYGLTF_IMPLEMENTATION
#define TINYGLTF_NO_STB_IMAGE
#define TINYGLTF_NO_STB_IMAGE_WRITE
#include <tiny_gltf.h>

namespace tinygltf {

bool LoadImageData(Image*, const int, std::string* err, std::string*, int, int, const unsigned char*, int, void*) {
  if (err) *err += "tinygltf's own image decoding is not in the browser build (the kit decodes images itself)\n";
  return false;
}

bool WriteImageData(const std::string*, const std::string*, const Image*, bool, std::string*, void*) { return false; }

}  // namespace tinygltf
