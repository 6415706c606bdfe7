#ifndef FOVEA_CORE_EVAL_UOIS_METRICS_H_
#define FOVEA_CORE_EVAL_UOIS_METRICS_H_

#include <opencv2/core.hpp>
#include <vector>

namespace fovea {

// The metrics of learned unseen-object instance segmentation (Xie et al.
// 2020, UOIS-Net; Xiang et al. 2021), so that Fovea's figures can be set
// beside theirs. Per scene, ground-truth objects and predicted segments are
// matched one to one by the Hungarian algorithm on their pairwise F
// (MaxWeightAssignment):
//   overlap P = matched true-positive pixels / all segment pixels,
//   overlap R = matched true-positive pixels / all object pixels,
//   boundary P/R: the same on one-pixel boundaries (mask pixels with a
//     4-neighbour outside), a boundary pixel counting when the matched
//     partner's boundary lies within ceil(0.003 x image diagonal) pixels,
//   objects_075 = share of objects whose matched F exceeds 0.75.
// Unmatched segments lower precision (their pixels are in the
// denominator); unmatched objects lower recall.
struct UoisScore {
  double overlap_p = 0.0, overlap_r = 0.0, overlap_f = 0.0;
  double boundary_p = 0.0, boundary_r = 0.0, boundary_f = 0.0;
  double objects_075 = 0.0;
  int objects = 0;   // ground-truth objects scored
  int segments = 0;  // predicted segments scored
};

// `objects`: CV_32SC1, 0 for no object, else an object id; `segments`:
// CV_32SC1, -1 for no segment, else a segment id (ids need not be
// contiguous). Objects of fewer than `min_object_pixels` pixels are left
// out (as background). A scene with neither objects nor segments scores 1
// everywhere; with segments but no objects, P = 0 and R = 1.
UoisScore ScoreUois(const cv::Mat& objects, const cv::Mat& segments,
                    int min_object_pixels = 1);

// The boundary tolerance for an image of this size, pixels.
int BoundaryTolerancePx(cv::Size size);

}  // namespace fovea

#endif  // FOVEA_CORE_EVAL_UOIS_METRICS_H_
