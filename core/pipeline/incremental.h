#ifndef FOVEA_CORE_PIPELINE_INCREMENTAL_H_
#define FOVEA_CORE_PIPELINE_INCREMENTAL_H_

#include <chrono>
#include <opencv2/core.hpp>
#include <vector>

#include "absl/status/statusor.h"
#include "core/base/interrupt.h"
#include "core/frame/osd_pcd.h"
#include "core/frame/rgbd_frame.h"
#include "core/pipeline/detect.h"
#include "core/pipeline/segment.h"
#include "core/segmentation/inc.h"
#include "core/segmentation/rbf_svm.h"

namespace fovea {

// Anytime incremental segmentation (thesis section 3.3): objects in order
// of saliency, each as soon as it is final, until the scene is exhausted,
// max_objects are out or the time budget is spent.

struct IncrementalOptions {
  // Saliency: a Gaussian at each of these pixels (x = column u, y = row v)
  // when given, weighted (n - i) / n for the i-th of n so that the first is
  // the most salient (section 3.3.3); otherwise Detect's master map with
  // `detect` (SYM3D by default). `detect` prepares the scene either way.
  std::vector<cv::Point> attention_points;
  // The Gaussians' standard deviation at a 525 px focal length, scaled by
  // fx / 525, pixels: about an object's size at a metre. Learn scenes,
  // random-points protocol, F first: 0.61 / 0.72 / 0.58 at 20 / 50 / 100.
  float attention_sigma_px = 50.0f;
  DetectOptions detect;
  // A temporal cue (a camera that keeps looking, core/track): the pixels
  // that changed since the camera's last frame, CV_8UC1 at the frame's
  // size, non-zero where changed; empty: none. The saliency map becomes
  // (1 - change_weight) S + change_weight C, S the map above scaled to
  // max 1, C the change blurred over 1 % of the image's width and scaled to
  // max 1: attention goes first to what changed.
  cv::Mat change;
  float change_weight = 0.5f;
  int max_objects = 0;  // 0: no limit
  // Objects showing less visible area are fragments and are not reported
  // (they still leave the scene), m^2 (SegmentOptions::min_object_area_m2).
  double min_object_area_m2 = kMinObjectAreaM2;
  double time_budget_seconds = 0.0;  // 0: no budget; checked between objects
  IncOptions inc;
  // Each object's box on the support (SegmentedObject::geometry).
  BoxFitOptions box_fit;
  ObjectPointsOptions object_points;
};

// INVALID_ARGUMENT naming the field.
absl::Status Validate(const IncrementalOptions& options);

// The saliency map of section 3.3.3 for given attention points (CV_32FC1,
// `size`, max 1), as IncrementalOptions describes.
cv::Mat AttentionPointsSaliency(const std::vector<cv::Point>& points,
                                cv::Size size, float sigma_px);

// `saliency` (CV_32FC1) with the temporal cue of `change` (CV_8UC1, any
// size: resized to the map's), as IncrementalOptions::change describes.
cv::Mat WithChangeCue(const cv::Mat& saliency, const cv::Mat& change,
                      float weight);

// Runs INC: the points sink gets the attention points used (given ones, or
// Detect's), then each object goes to the object sink as it is final. The
// summary's stop is kDone (every surface left the scene), kMaxObjects or
// kTimeBudget; scene_coverage is the fraction of non-table surface pixels
// that left the scene. Errors: Validate's; FAILED_PRECONDITION without the
// relation SVM; NOT_FOUND without a support plane; `interrupt`'s (checked
// between stages and at every growth step); a sink's.
absl::StatusOr<SegmentSummary> RunSegmentIncremental(
    const RgbdFrame& frame, const IncrementalOptions& options,
    const RbfSvm* relation_svm, const SegmentSinks& sinks,
    const InterruptCheck& interrupt = {},
    std::chrono::steady_clock::time_point start =
        std::chrono::steady_clock::now());

// Relation SVM training examples of one labelled frame (IncTrainingSamples
// on the scene `detect` prepares from measured depth: MeasuredDepthOnly).
absl::StatusOr<std::vector<SvmSample>> CollectIncSamples(
    const LabelledFrame& frame, int group, const DetectOptions& detect,
    const IncOptions& inc);

}  // namespace fovea

#endif  // FOVEA_CORE_PIPELINE_INCREMENTAL_H_
