#ifndef FOVEA_CORE_SEGMENTATION_EBS_H_
#define FOVEA_CORE_SEGMENTATION_EBS_H_

// Edge-based segmentation, EBS (thesis section 3.2.3): three edge maps
// (colour, depth, curvature; edge_maps.h) are fused by naive Bayes with
// per-cue histograms learned from labelled frames (eq. 3.5) into one edge
// probability map, and the object at a fixation is the minimum-cost closed
// contour around it in that map (polar_contour.h, after Mishra et al.
// 2009). This header is the whole EBS interface.

#include <array>
#include <cstdint>
#include <opencv2/core.hpp>
#include <string>
#include <string_view>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "core/frame/organized_cloud.h"
#include "core/frame/osd_pcd.h"
#include "core/segmentation/edge_maps.h"
#include "core/segmentation/polar_contour.h"

namespace fovea {

// How one cue's values are binned. Bins are uniform in
// sqrt(|value| / max_value), so they are fine near 0 where most pixels lie
// and coarse in the tail; values past max_value fall into the last bin. A
// signed cue spreads [-max_value, max_value] over the bins, the first half
// negative.
struct CueBins {
  int bins = 32;            // [2, 1024]
  float max_value = 1.0f;   // > 0, in the cue's units (EdgeMaps)
  bool signed_cue = false;  // values may be negative
};

struct EbsTrainOptions {
  // The edge maps the model is trained on and must be applied to.
  EdgeMapOptions edge_maps;
  // Normals of the clouds built from LabelledFrames (CE depends on them).
  NormalOptions normals;
  // Bins of SC (8-bit Lab units: steps between objects are 10-100), SD
  // (fraction of depth: the table's slope reads < 0.02 at the default
  // radius, the smallest object on a table 0.05-0.1) and CE (signed to
  // match EdgeMapOptions::signed_curvature; a signed cue with unsigned
  // curvature leaves half its bins empty).
  CueBins color_bins = {32, 100.0f, false};
  CueBins depth_bins = {32, 0.5f, false};
  CueBins curvature_bins = {32, 1.0f, true};
  // A pixel is an edge when a pixel of another region lies within this
  // Chebyshev distance, pixels (1: both pixels next to a boundary; 2 also
  // their neighbours, where the Sobel and curvature windows still respond).
  // Regions: the table (labels 1-9) is one, each object (ObjectId) one;
  // label 0 (no data) is no region.
  int boundary_band_px = 2;
  // Pixels farther than boundary_band_px but within this many more pixels
  // of another region are left out of both histograms (the ground truth's
  // own uncertainty at edges), pixels, >= 0.
  int ignore_band_px = 2;
};

// OK, or INVALID_ARGUMENT naming the field.
absl::Status Validate(const EbsTrainOptions& options);
absl::Status Validate(const CueBins& bins);

// Which pixels of a labelled frame are edges: CV_8UC1 of the labels' size,
// 255 edge, 1 no edge, 0 left out (no region, no depth, or in the ignore
// band). `labels` is CV_32SC1 as in LabelledFrame; `xyz` (CV_32FC3, may be
// empty) removes pixels without depth. Errors: wrong types or sizes, bad
// band widths.
absl::StatusOr<cv::Mat> BoundaryLabels(const cv::Mat& labels,
                                       const cv::Mat& xyz, int boundary_band_px,
                                       int ignore_band_px);

// Pixels classified at p(E) > 0.5 against BoundaryLabels.
struct EdgeCounts {
  int64_t true_edge = 0;     // edge, p > 0.5
  int64_t missed_edge = 0;   // edge, p <= 0.5
  int64_t true_no_edge = 0;  // no edge, p <= 0.5
  int64_t false_edge = 0;    // no edge, p > 0.5
  double Accuracy() const;   // (true_edge + true_no_edge) / all; 0 if none
  // Mean of the recall on edges and on non-edges (edges are a few per cent
  // of the pixels, so plain accuracy rewards saying "no edge"); 0 if none.
  double BalancedAccuracy() const;
};

// Per cue (its own posterior with prior 0.5, pixels where it is defined)
// and fused (EdgeProbability, pixels with depth).
struct EbsEvaluation {
  EdgeCounts color, depth, curvature, fused;
};

// The trained edge statistics: for each cue c in {SC, SD, CE} the
// Laplace-smoothed histograms p(c | edge) and p(c | no edge), and the
// options the maps were computed with. Cheap to copy.
class EbsModel {
 public:
  // Number of cues, in the order colour, depth, curvature, and their names
  // in the text form and in messages.
  static constexpr int kCues = 3;
  static constexpr const char* kCueNames[kCues] = {"color", "depth",
                                                   "curvature"};

  // One cue's histograms: counts of training pixels per bin.
  struct Cue {
    CueBins bins;
    std::vector<int64_t> edge;     // bins.bins entries
    std::vector<int64_t> no_edge;  // bins.bins entries
  };

  // Builds the clouds (options.normals) and edge maps of `frames`, counts
  // their pixels (EbsTrainer) and returns the model. Errors: invalid
  // options, null or malformed frames, no edge or no non-edge pixels.
  static absl::StatusOr<EbsModel> Train(
      const std::vector<const LabelledFrame*>& frames,
      const EbsTrainOptions& options);
  // The same with the other EbsTrainOptions at their defaults.
  static absl::StatusOr<EbsModel> Train(
      const std::vector<const LabelledFrame*>& frames,
      const EdgeMapOptions& edge_maps, const NormalOptions& normals);

  // From counts (what EbsTrainer and Parse call). Errors: invalid options,
  // histograms of another length than their bins, negative counts, a cue
  // without any count on either side.
  static absl::StatusOr<EbsModel> FromCounts(
      const EbsTrainOptions& options, const std::array<Cue, kCues>& cues);

  // p(E | sc, sd, ce) of eq. 3.5: naive Bayes with prior p(E) = 0.5,
  //   p(E | x) = p(E) prod_c p(x_c | E) /
  //              (p(E) prod_c p(x_c | E) + p(~E) prod_c p(x_c | ~E)),
  // over the cues defined at the pixel (a NaN map value leaves its cue
  // out). CV_32FC1 in [0, 1] of the maps' size; 1 where the pixel has no
  // depth (maps.depth NaN), so that contours keep to measured surfaces.
  // `maps` must be computed with edge_map_options() (checked: the three
  // maps CV_32FC1 of one size).
  cv::Mat EdgeProbability(const EdgeMaps& maps) const;
  // ComputeEdgeMaps(cloud, edge_map_options()) then the above.
  cv::Mat EdgeProbability(const OrganizedCloud& cloud) const;

  // Text form: a magic first line "fovea-ebs-model", "version 1", the
  // options, then per cue its bins and both histograms, and "end".
  // Parse(Serialize()) gives an identical model.
  std::string Serialize() const;
  // Reads Serialize's form. Any corrupt, truncated or foreign text is
  // INVALID_ARGUMENT naming the line and what is wrong; never crashes.
  static absl::StatusOr<EbsModel> Parse(std::string_view text);

  // "ebs-v1-" and 8 hex digits of a hash of Serialize(): equal for equal
  // models, different (but for hash collisions) otherwise.
  std::string Version() const;

  // Counts of the model's classification at 0.5 on `frames` (clouds built
  // with the model's normal options). Errors as Train's.
  absl::StatusOr<EbsEvaluation> Evaluate(
      const std::vector<const LabelledFrame*>& frames) const;
  // The same on one cloud and its labels.
  absl::StatusOr<EbsEvaluation> Evaluate(const OrganizedCloud& cloud,
                                         const cv::Mat& labels) const;

  const EbsTrainOptions& options() const { return options_; }
  const EdgeMapOptions& edge_map_options() const { return options_.edge_maps; }
  const std::array<Cue, kCues>& cues() const { return cues_; }

 private:
  EbsModel() = default;

  EbsTrainOptions options_;
  std::array<Cue, kCues> cues_;
  // log p(bin | E) - log p(bin | ~E), per cue, from the counts.
  std::array<std::vector<float>, kCues> log_ratio_;
  // p(bin | ~E) / p(bin | E), per cue.
  std::array<std::vector<float>, kCues> inverse_ratio_;
};

// Accumulates the histograms of EbsModel over frames, one at a time (so a
// training tool needs one frame in memory).
class EbsTrainer {
 public:
  // Errors: invalid options.
  static absl::StatusOr<EbsTrainer> Create(const EbsTrainOptions& options);

  // Counts the edge and non-edge pixels (BoundaryLabels) of one frame.
  // Errors: a malformed frame (empty, types, sizes); nothing is counted.
  absl::Status Add(const LabelledFrame& frame);
  // The same on a cloud built with options().normals and its labels.
  absl::Status Add(const OrganizedCloud& cloud, const cv::Mat& labels);

  // The model of the counts so far. FAILED_PRECONDITION when no edge or no
  // non-edge pixel has been counted.
  absl::StatusOr<EbsModel> Finish() const;

  const EbsTrainOptions& options() const { return options_; }

 private:
  explicit EbsTrainer(const EbsTrainOptions& options);

  EbsTrainOptions options_;
  std::array<EbsModel::Cue, EbsModel::kCues> cues_;
};

}  // namespace fovea

#endif  // FOVEA_CORE_SEGMENTATION_EBS_H_
