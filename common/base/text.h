#pragma once
// Small text helpers the framework and the tools share.
#include <string>

namespace kit {

// `text` with its ASCII letters in lower case: names matched in any case (a GL_RENDERER,
// lab folders, a batch's own file names, file extensions).
std::string lower_case(std::string text);

}  // namespace kit
