#pragma once
// The pass probes' set-ups (labs 1, 4, 5, 6 and 7, whose files are whole passes): each pass drawn
// alone on a few texels, its inputs chosen so that one part of it shows (function_probes.h,
// FunctionProbe::pass). Labs 2 and 3's function probes come from their contract instead
// (lab_functions.h).
#include <vector>

#include "frames/function_probes.h"  // FunctionProbe

namespace kit::grade {

// Lab `lab`'s pass probes, in their order (empty for a lab without any).
std::vector<FunctionProbe> pass_probes(int lab);

}  // namespace kit::grade
