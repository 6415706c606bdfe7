#ifndef FOVEA_CORE_EVAL_SEGMENTATION_METRICS_H_
#define FOVEA_CORE_EVAL_SEGMENTATION_METRICS_H_

#include <opencv2/core.hpp>
#include <vector>

namespace fovea {

// Attention-driven segmentation scored as in thesis section 3.2.4 (Table
// 3.1). Objects are ObjectId(label) of a LabelledFrame's labels.

// A mask with the seed that produced it, in the order they were emitted.
struct SeededMask {
  cv::Point seed;  // pixel
  cv::Mat mask;    // CV_8UC1, non-zero = object; the labels' size
};

struct SegmentationScore {
  // Each mask belongs to the object its seed lies on; for it P = |mask and
  // object| / |mask|, R = |mask and object| / |object|, F = 2PR / (P + R).
  // Per object that received masks: "first" is its first mask's F, "best"
  // the highest, "all" the mean; each averaged over those objects. Only
  // meaningful when objects_with_mask > 0.
  double f_all = 0.0;
  double f_best = 0.0;
  double f_first = 0.0;
  double precision_all = 0.0;  // mean P and R of the masks, like f_all
  double recall_all = 0.0;
  int objects = 0;            // objects in the ground truth
  int objects_with_mask = 0;  // that received a mask seeded on them
  int masks = 0;
  // Masks whose seed lies on the table, on no object or outside the image.
  int false_masks = 0;
};

// Objects with fewer than `min_object_pixels` labelled pixels are not
// counted (a sliver of an object seen through a gap).
SegmentationScore ScoreSegmentation(const cv::Mat& labels,
                                    const std::vector<SeededMask>& masks,
                                    int min_object_pixels = 1);

// Whole-scene F (after the thesis's section 3.3.3): for each
// ground-truth object, the output segment that overlaps it most and F of
// that pair; 0 for an object no segment touches; averaged over the objects
// (of at least `min_object_pixels`). `segments` is CV_32SC1, segment id >=
// 0, -1 for none. Segments lying on the table are ignored: they neither
// help nor hurt. 1 for a scene without objects.
double WholeSceneF(const cv::Mat& labels, const cv::Mat& segments,
                   int min_object_pixels = 1);

}  // namespace fovea

#endif  // FOVEA_CORE_EVAL_SEGMENTATION_METRICS_H_
