#ifndef FOVEA_CORE_SEGMENTATION_COS_H_
#define FOVEA_CORE_SEGMENTATION_COS_H_

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "core/base/interrupt.h"
#include "core/base/stage_clock.h"
#include "core/frame/organized_cloud.h"
#include "core/scene/support_plane.h"
#include "core/segmentation/linear_svm.h"
#include "core/segmentation/patch_features.h"
#include "core/segmentation/planar_patches.h"

namespace fovea {

// COS, Compact Object Segmentation (thesis section 3.2.2): planar patches
// grown into objects from attention points, a linear SVM deciding on each
// neighbouring patch from colour similarity (eq. 3.2) and the compactness
// of the union (eq. 3.3-3.4).

struct CosOptions {
  // Patches with a pixel within this distance of the seed form the initial
  // object, pixels (thesis: 5).
  int seed_radius_px = 5;
  // Points sampled per patch for the convex hull of eq. 3.3, and at most
  // this many for one hull (sampled evenly from the patches' samples):
  // qhull is O(n log n), and 500 points place a hull's faces to a
  // millimetre on a table-top object.
  int hull_points_per_patch = 48;
  int max_hull_points = 480;
  // A patch joins when the SVM's decision value exceeds this (0: the SVM's
  // own boundary; below 0 favours joining).
  double min_decision = 0.0;
  // After growing, free patches of at most this many points whose every
  // neighbour is the object or the table join it: slivers along folds and
  // rims, too small for their plane or colour to mean much.
  int small_patch_points = 150;
  // An object stops growing at this many patches.
  int max_object_patches = 64;
  // A patch more than this fraction of whose pixels lie on the support
  // plane (SupportPlane::inliers) is the table: never part of an object.
  // Removing the support surface first is how the thesis's table-top
  // pipeline starts; the SVM then decides between objects.
  float max_support_fraction = 0.5f;
  // ... and so is a patch whose points lie on average less than this above
  // the support plane, metres (the table remnants along objects' feet that
  // the plane fit's normal test left out; TableSceneOptions'
  // min_object_height).
  float min_patch_height = 0.01f;
  // The support plane's inliers are taken as its patches (each connected
  // part one) instead of being grown point by point: most of a table
  // scene's points are the table (85 % of the labelled ones in the OSD
  // scenes), and growing them was most of the patches' time.
  bool support_from_inliers = true;
  // Pixels with depth but no normal (object rims, occluding edges) join a
  // 4-neighbouring patch at nearly the same depth, one pixel ring per pass,
  // this many passes: 8 is NormalOptions::max_half_window, the farthest a
  // pixel can be from the edge that left it without a normal. 0 leaves
  // them out of every mask (learn scenes: F(all) 0.79 instead of 0.89).
  int rim_passes = 8;
  PatchColorOptions color;
  PlanarPatchOptions patches;
};

absl::Status Validate(const CosOptions& options);

// The names of the SVM's features, in order: eq. 3.2's histogram
// correlation in [-1, 1], and eq. 3.3-3.4's mean distance to the
// camera-facing hull faces as log10(mm + 0.1).
const std::vector<std::string>& CosFeatureNames();

// What COS computes once per frame.
struct CosScene {
  PlanarPatches patches;
  std::vector<std::vector<float>> histograms;         // per patch
  std::vector<std::vector<Eigen::Vector3f>> samples;  // per patch
  std::vector<bool> support;                          // per patch
  std::vector<std::vector<int>> neighbours;           // per patch, sorted
  // Per patch, the bounding box of its pixels in patches.labels (rims
  // included; PlanarPatch::box is before the rims joined).
  std::vector<cv::Rect> label_boxes;
  // "patches", "patch_features": how long building it took.
  std::vector<StageTiming> timings;
};

// Patches, their colour histograms, point samples, support flags and
// neighbours, of the points in `region` (CV_8UC1 of the cloud's size,
// non-zero = use: TableScene::region, the support and what stands on it;
// empty = every point). Errors: invalid options, a region of another size.
absl::StatusOr<CosScene> BuildCosScene(const OrganizedCloud& cloud,
                                       const SupportPlane& plane,
                                       const CosOptions& options,
                                       const cv::Mat& region = cv::Mat());

// CV_8UC1 of the labels' size, 255 on the pixels of `patches`.
cv::Mat PatchesMask(const CosScene& scene, const std::vector<int>& patches);

// The bounding box of the pixels of `patches` (empty for none): where
// PatchesMask can be non-zero.
cv::Rect PatchesBox(const CosScene& scene, const std::vector<int>& patches);

// Per patch: the ObjectId most of its pixels carry in `labels` (CV_32SC1 of
// a LabelledFrame; 0 = table or none).
std::vector<int> PatchObjectIds(const CosScene& scene, const cv::Mat& labels);

// The features of joining `candidate` to the object made of `object`
// patches (CosFeatureNames order).
std::vector<double> CosJoinFeatures(const CosScene& scene,
                                    const std::vector<int>& object,
                                    int candidate, const CosOptions& options);

// One object cut out from one seed.
struct CosObject {
  cv::Mat mask;              // CV_8UC1, 255 on the object's patches
  std::vector<int> patches;  // in the order they joined
  // Squashed smallest SVM margin of a joined patch, 1 / (1 + e^-margin),
  // in (0.5, 1]; 1 when the initial patches are the object.
  double score = 1.0;
};

// Runs COS seed after seed on one scene. Objects are disjoint: a patch
// belongs to the first object that takes it, and later objects neither
// start from nor grow into taken patches. The seeds come most salient
// first, so the earlier object had the better claim; and a robot wants each
// object once, not a second, overlapping mask of the same thing.
class CosSegmenter {
 public:
  // `scene` and `svm` must outlive the segmenter.
  CosSegmenter(const CosScene& scene, const LinearSvm& svm,
               const CosOptions& options);

  // The object at `seed` (pixel), or nullopt when there is none to cut:
  // the seed's own patch is taken by an earlier object, or no free
  // non-table patch lies within seed_radius_px (the seed is on the table,
  // on no depth, or on noise). Checks `interrupt` before each growing step.
  absl::StatusOr<std::optional<CosObject>> Segment(
      cv::Point seed, const InterruptCheck& interrupt = {});

  // Per patch: the index of the object that took it, or -1.
  const std::vector<int>& owner() const { return owner_; }

 private:
  std::vector<int> InitialPatches(cv::Point seed) const;
  // Joins the free patches of at most small_patch_points whose every
  // neighbour is in the object or the table.
  void AbsorbEnclosedSmallPatches(std::vector<int>& object) const;

  const CosScene& scene_;
  const LinearSvm& svm_;
  const CosOptions options_;
  std::vector<int> owner_;
  int objects_ = 0;
};

// Training examples for COS's SVM from one frame with ground truth
// (`labels`: CV_32SC1 of LabelledFrame, ObjectId convention). Each patch
// belongs to the object most of its pixels belong to (0: table or none).
// For each object, grown from its largest patch: every free neighbouring
// patch gives a sample (+1 when it belongs to the object, -1 when to
// another object or the table), then the largest +1 patch joins and the
// samples are taken again, until none is left; so the SVM sees objects in
// the states growing passes through. `group` is stored in each sample.
std::vector<SvmSample> CosTrainingSamples(const CosScene& scene,
                                          const cv::Mat& labels, int group,
                                          const CosOptions& options);

}  // namespace fovea

#endif  // FOVEA_CORE_SEGMENTATION_COS_H_
