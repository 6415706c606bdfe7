#ifndef FOVEA_CORE_SEGMENTATION_PATCH_FEATURES_H_
#define FOVEA_CORE_SEGMENTATION_PATCH_FEATURES_H_

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <vector>

#include "absl/status/status.h"
#include "core/frame/organized_cloud.h"

namespace fovea {

// What COS (thesis section 3.2.2) measures between a growing object and a
// candidate patch: colour similarity (eq. 3.2) and the compactness of their
// union (eq. 3.3-3.4).

struct PatchColorOptions {
  // HSV histogram: hue x saturation bins for coloured pixels ...
  int hue_bins = 8;
  int saturation_bins = 2;
  // ... and value bins for grey pixels, whose hue is noise (saturation
  // below `min_saturation` or value below `min_value`, 8-bit units).
  int gray_bins = 4;
  int min_saturation = 40;
  int min_value = 30;
};

absl::Status Validate(const PatchColorOptions& options);

// Bins of one histogram with these options.
int HistogramBins(const PatchColorOptions& options);

// Per label l in [0, label_count) of `labels` (CV_32SC1; other values are
// ignored), the counts of its pixels' colours (`rgb` CV_8UC3, same size) in
// the HSV histogram above: label_count rows of HistogramBins columns.
std::vector<std::vector<float>> LabelColorHistograms(
    const cv::Mat& rgb, const cv::Mat& labels, int label_count,
    const PatchColorOptions& options);

// Eq. 3.2: Pearson correlation of two histograms of the same size, in
// [-1, 1]; 0 when either is constant (an empty patch).
float HistogramCorrelation(const std::vector<float>& a,
                           const std::vector<float>& b);

// Up to `per_label` points of each label's valid pixels, spread evenly
// over the label's pixels in raster order.
std::vector<std::vector<Eigen::Vector3f>> SampleLabelPoints(
    const OrganizedCloud& cloud, const cv::Mat& labels, int label_count,
    int per_label);

// Eq. 3.3-3.4: the mean, over `points`, of each point's shortest distance to
// the faces of the points' 3D convex hull that face the camera (the origin
// lies outside the face's plane), metres. The visible surface of a convex
// object lies on those faces, so the value is near the sensor noise; a
// concavity between two objects, or a table patch in front of an object,
// lies far below them. Fewer than 4 points, or points on one plane, give 0.
float CameraFacingHullDistance(const std::vector<Eigen::Vector3f>& points);

// Each point's distance of CameraFacingHullDistance (all 0 for fewer than
// 4 points or points on one plane).
std::vector<float> CameraFacingHullDistances(
    const std::vector<Eigen::Vector3f>& points);

}  // namespace fovea

#endif  // FOVEA_CORE_SEGMENTATION_PATCH_FEATURES_H_
