#ifndef FOVEA_CORE_SEGMENTATION_INC_H_
#define FOVEA_CORE_SEGMENTATION_INC_H_

#include <memory>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

#include "absl/status/statusor.h"
#include "core/base/interrupt.h"
#include "core/frame/organized_cloud.h"
#include "core/frame/support_plane.h"
#include "core/segmentation/cos.h"
#include "core/segmentation/rbf_svm.h"
#include "core/segmentation/relations.h"
#include "core/segmentation/surface_model.h"

namespace fovea {

// INC, incremental attention-driven segmentation (thesis section 3.3,
// Algorithm 1): the most salient surface starts an object; the surfaces
// around it are grouped by a graph-based segmentation whose edge weights
// come from an SVM on surface relations; the selection grows by its
// neighbours until the object stops changing; the object is emitted, its
// surfaces leave the scene, and the next most salient surface starts the
// next object.

struct IncOptions {
  // Low-level surfaces: COS's planar patches with their rims and support
  // flags (adaptive clustering by normals: a point joins when its normal
  // deviation and plane distance are below thresholds, the distance one
  // growing with depth as the Kinect's noise, z^2).
  CosOptions surfaces;
  RelationOptions relations;
  // Graph-based segmentation (Felzenszwalb and Huttenlocher 2004): two
  // groups merge when the edge between them weighs at most
  // min(Int(A) + k / |A|, Int(B) + k / |B|), |.| in surfaces, weights
  // 1 - p(same object). k = 1: a lone surface always joins its most likely
  // neighbour (lone surfaces are fragments more often than objects); two
  // groups of two merge when p(same) exceeds 1/2 - Int. Learn scenes:
  // whole-scene F 0.889 / 0.914 / 0.917 / 0.919 / 0.859 for k = 0.5 / 0.75
  // / 1 / 1.25 / 2.
  double k = 1.0;
  // Surface models (plane or B-spline by MDL); two neighbouring surfaces
  // whose union is better explained by one B-spline are one surface for
  // the grouping (their edge weighs 0).
  bool fuse_surfaces = true;
  SurfaceModelOptions surface_models;
  // Objects of fewer points leave the scene without being emitted (noise
  // surfaces), pixels.
  int min_object_points = 150;
  // The selection grows by its neighbours at most this many times per
  // object.
  int max_growth_steps = 12;
};

absl::Status Validate(const IncOptions& options);

// What INC computes once per frame.
struct IncScene {
  CosScene surfaces;
  std::unique_ptr<RelationComputer> relations;
  // Per surface, eq. 3.6: the mean of the map over its pixels (0 for the
  // support's, which never start or join an object).
  std::vector<double> saliency;
  std::vector<int> pixels;  // per surface, in the labels image (0: support)
  // Per surface, its points (none for support ones), for the surface models
  // (options.fuse_surfaces), which the segmenter fits only for the
  // surfaces an object's growth reaches, when it first reaches them.
  std::vector<std::vector<Eigen::Vector3f>> points;
  int object_points = 0;  // pixels of non-support surfaces
  // The surfaces' stages, then "relations" and "surface_points".
  std::vector<StageTiming> timings;
};

// Surfaces (of the points in `region`, as BuildCosScene), their
// relations' statistics and saliency from `saliency_map`
// (CV_32FC1 of the cloud's size, [0, 1]; NaN read as 0). Errors: invalid
// options, a map of another size or type.
absl::StatusOr<IncScene> BuildIncScene(const OrganizedCloud& cloud,
                                       const SupportPlane& plane,
                                       const cv::Mat& saliency_map,
                                       const IncOptions& options,
                                       const cv::Mat& region = cv::Mat());

// The same from `surfaces`, which BuildCosScene made of the same cloud and
// plane with options.surfaces (so that a caller can build them while it
// computes the saliency map).
absl::StatusOr<IncScene> BuildIncScene(CosScene surfaces,
                                       const OrganizedCloud& cloud,
                                       const SupportPlane& plane,
                                       const cv::Mat& saliency_map,
                                       const IncOptions& options);

struct IncObject {
  cv::Mat mask;               // CV_8UC1, 255 on the object
  cv::Rect box;               // the mask's bounding box
  std::vector<int> surfaces;  // its surfaces
  int seed_surface = -1;      // the most salient one, which started it
  cv::Point seed;             // a pixel of it near its centroid
  double saliency = 0.0;      // the seed surface's
  double score = 0.0;         // mean p(same) of the object's merged edges
  int growth_steps = 0;
};

// Runs Algorithm 1 object by object on one scene.
class IncSegmenter {
 public:
  // Not owned; all must outlive the segmenter.
  IncSegmenter(const IncScene& scene, const RbfSvm& svm,
               const IncOptions& options);

  // The next object, most salient first; nullopt once no surface is left.
  // Checks `interrupt` at every growth step.
  absl::StatusOr<std::optional<IncObject>> Next(
      const InterruptCheck& interrupt = {});

  // Fraction of the non-support surface pixels that left the scene.
  double coverage() const;

 private:
  double SameProbability(int a, int b);
  // Fits the surface models of `selection`'s surfaces and decides for each
  // neighbouring pair of them whether one B-spline explains both (then
  // their edge weighs 0), where not done before; in parallel.
  void DecideFusions(const std::vector<int>& selection);
  // Groups of `selection` by the graph-based segmentation; the group of
  // `seed`.
  std::vector<int> GroupOf(const std::vector<int>& selection, int seed,
                           double* score);

  const IncScene& scene_;
  const RbfSvm& svm_;
  const IncOptions options_;
  std::vector<bool> removed_;
  int removed_points_ = 0;
  std::unordered_map<uint64_t, double> probability_;  // pair -> p(same)
  // Per surface: fitted yet, and its model (none: support, too few points
  // or degenerate).
  std::vector<char> fitted_;
  std::vector<std::optional<SurfaceModel>> models_;
  std::unordered_map<uint64_t, bool> fused_;  // pair -> one B-spline
};

// Relation SVM training examples of one labelled frame: every pair of
// neighbouring non-support surfaces, +1 when most of both belong to one
// ground-truth object, -1 when to different ones (or one to the table).
// Pairs of two table surfaces are left out. `group` tags the samples.
std::vector<SvmSample> IncTrainingSamples(const IncScene& scene,
                                          const cv::Mat& labels, int group);

}  // namespace fovea

#endif  // FOVEA_CORE_SEGMENTATION_INC_H_
