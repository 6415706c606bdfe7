#ifndef FOVEA_CORE_FRAME_HOLE_FILLING_H_
#define FOVEA_CORE_FRAME_HOLE_FILLING_H_

#include <opencv2/core.hpp>

#include "absl/status/statusor.h"
#include "core/frame/rgbd_frame.h"

namespace fovea {

struct HoleFillingOptions {
  // Holes (8-connected regions without depth) larger than this stay empty,
  // pixels: 2000 is a 45 x 45 px shadow, about 8 cm at 1 m.
  int max_hole_pixels = 2000;
  // Colour similarity scale of the diffusion weights, 8-bit RGB units
  // (the sigma of exp(-|c_i - c_j|^2 / (2 sigma^2))): neighbours across a
  // colour edge of a few sigma contribute almost nothing.
  float color_sigma = 12.0f;
  // Smoothing sweeps of the anisotropic diffusion after the holes are
  // reached (Jacobi iterations on the hole pixels, known pixels fixed).
  int diffusion_iterations = 10;
};

absl::Status Validate(const HoleFillingOptions& options);

struct FilledDepth {
  cv::Mat depth;   // CV_32FC1 metres; holes up to the size limit filled
  cv::Mat filled;  // CV_8UC1, 255 where the depth was filled here
  int filled_pixels = 0;
};

// Fills missing depth (shadows, black and shiny surfaces) by colour-guided
// anisotropic diffusion (thesis section 2.2, after Varadarajan & Vincze
// 2012): depth flows into a hole from its border, each pixel taking the
// average of its 8 neighbours with depth weighted by colour similarity, so
// depth travels along paths of similar colour and not across colour edges;
// then `diffusion_iterations` sweeps of the same weighted averaging smooth
// the filled values. Holes larger than `max_hole_pixels`, and holes with no
// valid border pixel, stay empty (NaN). Original depths never change.
absl::StatusOr<FilledDepth> FillDepthHoles(const RgbdFrame& frame,
                                           const HoleFillingOptions& options);

}  // namespace fovea

#endif  // FOVEA_CORE_FRAME_HOLE_FILLING_H_
