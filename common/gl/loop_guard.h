#pragma once
// Loops that end, in the browser. A shader whose loop never ends keeps a software GPU
// (SwiftShader, what Chromium draws WebGL with where it has no usable GPU) busy for good:
// no watchdog ends the draw, and the page, then the whole browser, stops answering. The
// desktop ends such a shader by its process's CPU time (kit-grade's limits); a browser
// has nothing to end. So every loop of a shader compiled for WebGL2 asks one counter
// before each iteration, and the loops of one invocation stop after a stated number of
// iterations. A shader whose loops stay under that count draws exactly what it drew
// without the counter; one that would run forever draws a frame, in bounded time.
#include <cstdint>

#include "gl/shader_source.h"

namespace kit {

// The iterations every invocation may run, in all its loops together. Lab loops need far
// fewer in passes drawn at the frame's size (lab 2's lights, lab 5's blur taps); 1,024 a
// pixel of a 640x480 frame is 3 x 10^8 iterations, about a second of SwiftShader on two
// cores for a loop with sines in it.
constexpr int kLoopIterationsPerInvocation = 1024;
// A full-screen pass of W x H pixels may run this many iterations in all, whichever is
// more a pixel: lab 6's maps are small and sum many samples a texel (the irradiance map
// 32x16 texels, each summing 128x64 of the environment's, needs 8,256 a texel and gets
// 524,288).
constexpr std::int64_t kLoopIterationsPerPass = std::int64_t{1} << 28;
// The iterations each invocation of a full-screen pass of width x height may run.
int loop_budget(int width, int height);

// The uniform a guarded shader reads its budget from (FullscreenTriangle sets it; a draw
// that does not reads 0 and gets kLoopIterationsPerInvocation), and the prefix of every
// name the guard adds: a lab file may not use it.
constexpr const char* kLoopBudgetUniform = "kit_loop_budget_";
constexpr const char* kLoopGuardPrefix = "kit_loop_";

// Rewrites each `for`, `while` and `do ... while` of `shader` (the output of
// translate_to_glsl_es) so that its condition asks the counter first, and declares the
// counter on the precision line (so no line moves: errors still name the student's files
// and lines). A shader without a loop is left as it is. Loops inside #define lines are
// guarded where they are written. Throws kit::Error "FILE:LINE: ..." where a loop cannot
// be guarded: a loop word whose condition a macro supplies from elsewhere, a condition that
// declares a variable, token pasting (##, which could spell a loop word), or a name
// starting with kLoopGuardPrefix.
void guard_loops(AssembledShader& shader);

}  // namespace kit
