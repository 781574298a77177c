#pragma once
// The page's "Check my lab": the lab's grading renders drawn on the student's GPU at the
// grader's sizes and settings (tools/grade/frames/lab_frames.h) and compared with the shipped
// references by kit-grade's own rules (tools/grade/verdict/lab_verdict.h), compiled to WebAssembly
// with the rest of kit-web. A preview: the grade is ./kit grade's or the platform's.
#include <filesystem>

#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "images/image_io.h"

namespace kit::web {

// `image` (rows top-down, one to four float channels) as RGBA8 the way kit-render's PNG writer
// makes the bytes (to_unorm8; grey from one channel), opaque; rows bottom-up for a GL texture.
std::vector<unsigned char> rgba8(const Image& image, bool bottom_up);

// Per lab: its checks (key, title, points).
nlohmann::json check_catalogue();

// Per lab: the scenes its checks render, which the page fetches before a check where the
// site keeps them apart from the first frame's files (tools/web/site_files.py).
nlohmann::json check_scenes();

// Checks lab `lab` of the lab files under `lab_root` (NN-name folders), writing each
// check's images into `out` (a folder it empties first) as raw RGBA8 files the page draws
// (<key>.image.rgba, .reference.rgba, .diff.rgba). The answer: the lab's status and
// message, each check's verdict, numbers and images, the score, the likely mistakes.
// Needs a current GL context; throws kit::Error only for the kit's own problems (a
// reference it cannot read).
nlohmann::json run_check(int lab, const std::filesystem::path& lab_root, const std::filesystem::path& out);

}  // namespace kit::web
