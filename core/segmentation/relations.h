#ifndef FOVEA_CORE_SEGMENTATION_RELATIONS_H_
#define FOVEA_CORE_SEGMENTATION_RELATIONS_H_

#include <Eigen/Core>
#include <cstdint>
#include <opencv2/core.hpp>
#include <string>
#include <unordered_map>
#include <vector>

#include "absl/status/status.h"
#include "core/frame/organized_cloud.h"
#include "core/segmentation/patch_features.h"

namespace fovea {

// Relations between neighbouring surfaces (thesis section 3.3.2, after
// Richtsfeld et al. 2012), each normalised to [0, 1]: what INC's relation
// SVM decides from whether two surfaces belong to one object.

struct RelationOptions {
  PatchColorOptions color;
  // Gabor bank on the grey image at half resolution: 4 orientations x these
  // wavelengths, pixels of the half-resolution image.
  std::vector<float> gabor_wavelengths_px = {3.0f, 6.0f};
  // Fourier texture: up to this many 16x16 windows per surface (at half
  // resolution), their DFT magnitude summed in 4 radial bands.
  int fourier_windows = 8;
  // Scales that map raw border statistics to [0, 1] (value / scale,
  // clamped): Lab colour difference (a JND is ~2.3; 50 is "different"),
  // depth step as a fraction of depth, normal angle in degrees.
  float color_scale = 50.0f;
  float depth_scale = 0.05f;
  float angle_scale_deg = 90.0f;
  // Two 4-neighbours across a border are a 3D border (the surfaces touch in
  // space) when their depths differ by at most this fraction of depth.
  float touch_depth_fraction = 0.02f;
  // Convexity across a border (after Stein et al. 2014, LCCP): for each
  // 4-adjacent pixel pair across it that touches (touch_depth_fraction), the
  // points this many pixels inside either surface, p and q, and their normals
  // give c = (n_q - n_p) . (q - p) / |q - p|: > 0 where the surfaces fold away
  // from each other (the faces of one box), < 0 where they fold towards
  // each other (a tin standing on a box, a can in a bowl), about 0 on one
  // smooth surface. 3 px is 6 mm at 1 m, beyond the pixels whose normals
  // straddle the border.
  int convexity_offset_px = 3;
  // c below minus this is a sharp concave fold: 0.25 is about 15 degrees.
  float sharp_concave = 0.25f;
};

absl::Status Validate(const RelationOptions& options);

// The relation features' names, in order.
const std::vector<std::string>& RelationFeatureNames();

// Indices of the border features a geometric rule reads (IncOptions::
// convex_join): the share of the border where the surfaces touch in 3D,
// the mean convexity mapped to [0, 1] (0.5 flat, above convex) and the
// share of sharp concave folds.
inline constexpr int kBorder3dFractionFeature = 10;
inline constexpr int kBorderConvexityFeature = 12;
inline constexpr int kBorderSharpConcaveFeature = 13;

// Per-frame statistics of the surfaces of `labels` (CV_32SC1, -1 = none;
// surfaces 0 .. count-1): colour histograms, texture energies and, for
// every 4-adjacent pair, the statistics along their shared border.
class RelationComputer {
 public:
  // `up`: the support's normal (unit, pointing away from the support, into
  // the half space the objects stand in), for the relations to gravity.
  RelationComputer(const OrganizedCloud& cloud, const cv::Mat& labels,
                   int count, const Eigen::Vector3f& up,
                   const RelationOptions& options);

  // The features of the pair (a, b), RelationFeatureNames() order. A pair
  // that shares no border gets border features of 0.
  std::vector<double> Relate(int a, int b) const;

  // Pairs (a < b) that share a border, sorted.
  const std::vector<std::pair<int, int>>& adjacent_pairs() const {
    return pairs_;
  }

 private:
  struct Border {
    int pixels = 0;    // 4-adjacent pixel pairs across the border
    int touching = 0;  // of which the depths agree (3D border)
    double color_sum = 0, color_sq = 0;
    double depth_sum = 0, depth_sq = 0;
    double angle_sum = 0, angle_sq = 0;
    int folds = 0;  // pairs whose convexity could be measured
    double convexity_sum = 0;
    int sharp_concave = 0;
  };
  static uint64_t Key(int a, int b);

  RelationOptions options_;
  std::vector<std::vector<float>> histograms_;
  std::vector<std::vector<double>> gabor_;
  std::vector<std::vector<double>> fourier_;
  std::vector<int> points_;
  std::vector<double> curvature_;    // mean 1 - n . (mean normal)
  std::vector<double> uprightness_;  // |mean normal . up|, [0, 1]
  std::unordered_map<uint64_t, Border> borders_;
  std::vector<std::pair<int, int>> pairs_;
};

}  // namespace fovea

#endif  // FOVEA_CORE_SEGMENTATION_RELATIONS_H_
