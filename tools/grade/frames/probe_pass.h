#pragma once
// The function probes' off-screen pass (function_probes.h), run by the render worker after
// a lab's renders with the same GL context: for each probe shader of the lab, one program
// with every probed function's call, or, when that does not build (a file that lacks a
// function or changed its signature), one program per function, so that the others are
// still probed. Each probe is one draw of a row of pixels, one per case, read back as floats.
#include <filesystem>
#include <map>
#include <string>

#include <nlohmann/json_fwd.hpp>

#include "frames/function_probes.h"
#include "render/stages.h"

namespace kit::grade {

// Every probe of `stage`'s lab on the lab files in `lab_root`, by probe id, at the inputs of
// `reference` (probes.json; function_probes.h, probes_to_run). A probe whose
// function could not be built gets its error instead of values. Throws kit::Error on a GL
// error (the worker reports it as a render error).
std::map<std::string, ProbeValues> run_function_probes(const Stage& stage, const std::filesystem::path& lab_root,
                                                       const nlohmann::json& reference);

// The same, written where a render worker's report (child.json) and the page's check keep
// them for probe_outcomes: "probes" (by id, probe_values_json), or "probes_error" when a GL
// error stopped the pass. They only inform: a probe that cannot run changes no lab's status.
// Nothing for a lab without probes.
void report_function_probes(const Stage& stage, const std::filesystem::path& lab_root, const nlohmann::json& reference,
                            nlohmann::json& report);

}  // namespace kit::grade
