#pragma once
// A lab's contract, read from tools/grade/lab_functions.json: the functions a lab declares with
// a fixed signature (lab 2's BRDF terms, lab 3's falloff and tone map) and the inputs the
// grader probes them at. Renaming, adding or removing a lab function is an edit of that file
// and the lab's files; the probe shaders are written from it (tools/grade/lab_contract.py).
// The file's "about" says how its cases are written.
#include <nlohmann/json_fwd.hpp>

#include <filesystem>
#include <string>
#include <vector>

#include "frames/function_probes.h"  // FunctionProbe

namespace kit::grade {

// <kit root>/tools/grade/lab_functions.json.
std::filesystem::path default_lab_functions_path();

// The function probes the contract lists for lab `lab`, in its order (empty where it lists
// none). Throws kit::Error naming `where` (the file), the element and what is wrong with it.
std::vector<FunctionProbe> contract_function_probes(const nlohmann::json& contract, int lab, const std::string& where);

// The same from the default file, read once per process.
std::vector<FunctionProbe> contract_function_probes(int lab);

}  // namespace kit::grade
