#include "bench_metrics.h"

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "base/error.h"

namespace kit::bench {

namespace {

OIIO::ImageBuf wrap(const Image& image) {
  OIIO::ImageSpec spec(image.width, image.height, image.channels, OIIO::TypeDesc::FLOAT);
  // Wraps the caller's pixels (no copy); the Image outlives the comparison.
  return OIIO::ImageBuf(spec, const_cast<float*>(image.pixels.data()));
}

}  // namespace

ErrorFigures compare_images(const Image& image, const Image& reference) {
  if (image.width != reference.width || image.height != reference.height || image.channels != reference.channels)
    throw Error("compare_images: images differ in size or channel count");
  OIIO::ImageBuf a = wrap(image), b = wrap(reference);
  OIIO::ROI rgb = a.roi();
  rgb.chend = std::min(image.channels, 3);
  OIIO::ImageBufAlgo::CompareResults r = OIIO::ImageBufAlgo::compare(
      a, b, static_cast<float>(kDisplayStep), static_cast<float>(kDisplayStep), rgb);
  // r.error only says some pixel exceeded failthresh (nfail > 0), which is a figure here.
  // r.PSNR takes the larger of 1 and the brightest value as its peak; the bench keeps 1.0
  // (display white) so HDR figures of different methods share one peak.
  ErrorFigures e;
  e.max_abs = r.maxerror;
  e.psnr = r.rms_error > 0.0 ? 20.0 * std::log10(1.0 / r.rms_error) : std::numeric_limits<double>::infinity();
  e.frac_over_step = static_cast<double>(r.nfail) / (static_cast<double>(image.width) * image.height);
  e.non_finite = count_non_finite(image);
  return e;
}

}  // namespace kit::bench
