#pragma once
// The one include for GL declarations: the glad loader generated at configure time
// (cmake/glad.cmake). glad 2 writes <glad/gl.h>, glad 0.1 (Ubuntu 22.04) <glad/glad.h>.
#if KIT_GLAD_GENERATION == 1
#include <glad/glad.h>
#else
#include <glad/gl.h>
#endif

#include <string>

namespace kit {

// Throws kit::Error naming `where` if glGetError reports anything.
void check_gl(const char* where);

}  // namespace kit
