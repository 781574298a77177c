#pragma once
// Each light's share of a reference frame, pixel by pixel: what a failed lit check's worst
// pixel says of the lights there (lab_verdict.h, describe_pixel_inputs). Made by
// --update-references from the solutions' own frames, each light drawn alone
// (RenderSettings::only_light) less the frame with none, so it holds no formula of a lab.
//
// One RGBA float image per lit frame (checks.h, RenderSpec::light_shares): in R, G and B the
// three lights that give the pixel the most luminance, most first, each as
//   number + share / 2
// (number: the light's place in the scene's list, from 1; share: of the summed luminance of
// every light there, in [0, 1], to 1/256), 0 where there is none; in A that summed luminance
// (linear HDR, Rec. 709 weights as shaders/math.glsl's KIT_LUMINANCE, to 7 significant bits).
// Emission and stage 6's environment are in the frame with no light, so in no light's share.
#include <string>
#include <vector>

#include "images/image_io.h"

namespace kit::grade {

// Lights past this many are summed in A but not named.
constexpr int kSharedLights = 3;

// `alone[i]`: the frame's HDR image with light i alone; `none`: with no light. All the same size.
Image light_shares_image(const std::vector<Image>& alone, const Image& none);

struct LightShare {
  int light = 0;        // index in the scene's list, from 0
  double share = 0.0;   // of the lights' summed luminance
};
struct PixelLightShares {
  double luminance = 0.0;         // every light's, summed
  std::vector<LightShare> lights;  // most first, at most kSharedLights, none with share 0
};
// One pixel of a light_shares_image (nothing outside it).
PixelLightShares light_shares_at(const Image& shares, int x, int y);

// Where two light-share images of one frame disagree beyond what renderers differ by: more
// than 0.5 % of the pixels (edges, where a rasteriser may cover another surface) with the
// summed luminance off by more than an HDR check's threshold (0.01 after c / (1 + c)), or
// another light most where it gives at least 60 % in both; "" when they agree.
std::string compare_light_shares(const Image& made, const Image& stored);

}  // namespace kit::grade
