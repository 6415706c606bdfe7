#include "core/eval/segmentation_metrics.h"

#include <algorithm>
#include <map>

#include "core/frame/osd_pcd.h"

namespace fovea {

SegmentationScore ScoreSegmentation(const cv::Mat& labels,
                                    const std::vector<SeededMask>& masks,
                                    int min_object_pixels) {
  std::map<int, int> object_pixels;
  for (int v = 0; v < labels.rows; ++v) {
    const int* label = labels.ptr<int>(v);
    for (int u = 0; u < labels.cols; ++u) {
      const int object = ObjectId(label[u]);
      if (object > 0) ++object_pixels[object];
    }
  }
  SegmentationScore score;
  for (const auto& [object, pixels] : object_pixels) {
    score.objects += pixels >= min_object_pixels ? 1 : 0;
  }
  struct PerObject {
    double first = 0.0, best = 0.0, sum = 0.0, p_sum = 0.0, r_sum = 0.0;
    int count = 0;
  };
  std::map<int, PerObject> per_object;
  for (const SeededMask& m : masks) {
    ++score.masks;
    const cv::Point s = m.seed;
    const bool inside =
        s.x >= 0 && s.y >= 0 && s.x < labels.cols && s.y < labels.rows;
    const int object = inside ? ObjectId(labels.at<int>(s.y, s.x)) : 0;
    const auto found = object_pixels.find(object);
    if (object == 0 || found == object_pixels.end() ||
        found->second < min_object_pixels) {
      ++score.false_masks;
      continue;
    }
    int mask_pixels = 0;
    int overlap = 0;
    for (int v = 0; v < labels.rows; ++v) {
      const int* label = labels.ptr<int>(v);
      const unsigned char* in = m.mask.ptr<unsigned char>(v);
      for (int u = 0; u < labels.cols; ++u) {
        if (in[u] == 0) continue;
        ++mask_pixels;
        overlap += ObjectId(label[u]) == object ? 1 : 0;
      }
    }
    const double p =
        mask_pixels > 0 ? static_cast<double>(overlap) / mask_pixels : 0.0;
    const double r = static_cast<double>(overlap) / found->second;
    const double f = p + r > 0.0 ? 2.0 * p * r / (p + r) : 0.0;
    PerObject& o = per_object[object];
    if (o.count == 0) o.first = f;
    o.best = std::max(o.best, f);
    o.sum += f;
    o.p_sum += p;
    o.r_sum += r;
    ++o.count;
  }
  score.objects_with_mask = static_cast<int>(per_object.size());
  if (score.objects_with_mask > 0) {
    for (const auto& [object, o] : per_object) {
      score.f_first += o.first;
      score.f_best += o.best;
      score.f_all += o.sum / o.count;
      score.precision_all += o.p_sum / o.count;
      score.recall_all += o.r_sum / o.count;
    }
    const double n = score.objects_with_mask;
    score.f_first /= n;
    score.f_best /= n;
    score.f_all /= n;
    score.precision_all /= n;
    score.recall_all /= n;
  }
  return score;
}

double WholeSceneF(const cv::Mat& labels, const cv::Mat& segments,
                   int min_object_pixels) {
  std::map<int, int> object_pixels;
  std::map<int, int> segment_pixels;
  std::map<std::pair<int, int>, int> overlap;  // (object, segment)
  for (int v = 0; v < labels.rows; ++v) {
    const int* label = labels.ptr<int>(v);
    const int* segment = segments.ptr<int>(v);
    for (int u = 0; u < labels.cols; ++u) {
      const int object = ObjectId(label[u]);
      if (object > 0) ++object_pixels[object];
      if (segment[u] >= 0) {
        ++segment_pixels[segment[u]];
        if (object > 0) ++overlap[{object, segment[u]}];
      }
    }
  }
  double sum = 0.0;
  int objects = 0;
  for (const auto& [object, pixels] : object_pixels) {
    if (pixels < min_object_pixels) continue;
    ++objects;
    int best_overlap = 0;
    int best_segment = -1;
    for (auto it = overlap.lower_bound({object, -1});
         it != overlap.end() && it->first.first == object; ++it) {
      if (it->second > best_overlap) {
        best_overlap = it->second;
        best_segment = it->first.second;
      }
    }
    if (best_segment < 0) continue;
    const double p =
        static_cast<double>(best_overlap) / segment_pixels[best_segment];
    const double r = static_cast<double>(best_overlap) / pixels;
    sum += 2.0 * p * r / (p + r);
  }
  return objects > 0 ? sum / objects : 1.0;
}

}  // namespace fovea
