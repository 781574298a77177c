#pragma once
// The one include for GL declarations: the glad loader generated at configure time.
#include <glad/gl.h>

#include <string>

namespace kit {

// Throws kit::Error naming `where` if glGetError reports anything.
void check_gl(const char* where);

}  // namespace kit
