#ifndef FOVEA_CORE_FRAME_DROPOUT_FILL_H_
#define FOVEA_CORE_FRAME_DROPOUT_FILL_H_

#include <opencv2/core.hpp>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "core/base/interrupt.h"
#include "core/frame/hole_filling.h"
#include "core/frame/sensor_model.h"

namespace fovea {

// Speckled dropout: a dark surface whose depth the sensor returns at
// scattered pixels only (a structured-light camera on a black mug). Left as
// it is, no normal and no patch survives there: the gradients need both
// ends of their baseline and the patches grow over 4-neighbours, which do
// not connect once fewer than about 60 % of the pixels have depth. A
// shadow beside an edge or a hole on a surface that is otherwise whole is
// not speckle and is left alone. Cost: about 1 ms on a 640 x 480 frame,
// 100-145 ms on one dark and speckled all over (the call's deadline is
// asked within it).
struct DropoutFillOptions {
  // Half-size of the window around a missing pixel, pixels.
  int half_window = 3;
  // The window is speckled when both pixels with depth and pixels without
  // make up at least these fractions of it.
  float min_valid_fraction = 0.15f;
  float min_missing_fraction = 0.25f;
  // ... and scattered: at least this fraction of the window's pairs of
  // 4-neighbours are one with depth and one without (about 0.48 where 60 %
  // drop out at random; 0.1-0.2 along a shadow's or a cropped frame's
  // ragged edge).
  float min_transition_fraction = 0.3f;
  // Each quadrant of the window (the centre row and column in both) holds
  // at least this many pixels with depth: the pixel lies among them, not
  // beyond their edge.
  int min_quadrant_points = 1;
  // All but `max_outlier_fraction` of the pixels with depth lie within
  // this many sigma(z) of the plane fitted to them (z = a u + b v + c in
  // the window), sigma at least `min_sigma_m`: one surface, not two across
  // an edge.
  float max_residual_sigmas = 3.0f;
  float min_sigma_m = 0.001f;
  float max_outlier_fraction = 0.05f;
  // Passes in all: after the first (speckle), each fills the pixels left
  // missing within the window of one filled by the pass before, by the
  // plane test alone, from measured and filled depth.
  int passes = 5;
  // The call's interrupt is asked after every this many plane fits (8192
  // take about 5 ms): a frame with little to fill is never interrupted
  // inside (its stages' checks suffice), one dark and speckled all over
  // (over 100 ms) stops within a few milliseconds.
  int fits_per_interrupt_check = 8192;
  // Only dark pixels are filled (luma, 8-bit, at most this): the surfaces
  // whose depth a structured-light camera loses for their low reflectance.
  // A shadow's speckle on a bright table is not filled (an active-stereo
  // camera leaves one beside the objects it sees).
  int max_luma = 80;
};

absl::Status Validate(const DropoutFillOptions& options);

// Fills each missing pixel (NaN) of `depth` (CV_32FC1 metres) in speckled
// dropout with the depth at it of the plane through the window's measured
// pixels, then (options.passes) the gaps beside those. `color`: CV_8UC3 RGB
// of the depth's size. The result's depth shares `depth`'s pixels when
// nothing was filled, and is a copy otherwise. `interrupt` is asked as
// options.fits_per_interrupt_check says, and its error returned.
absl::StatusOr<FilledDepth> FillSpeckledDropout(
    const DropoutFillOptions& options, const SensorModel& sensor,
    const cv::Mat& color, const cv::Mat& depth,
    const InterruptCheck& interrupt = {});

}  // namespace fovea

#endif  // FOVEA_CORE_FRAME_DROPOUT_FILL_H_
