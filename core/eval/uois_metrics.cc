#include "core/eval/uois_metrics.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <opencv2/imgproc.hpp>

#include "core/eval/hungarian.h"

namespace fovea {
namespace {

// One labelled region: its pixel count and bounding box.
struct Region {
  int id = 0;
  int pixels = 0;
  cv::Rect box;
};

std::vector<Region> Regions(const cv::Mat& labels, int none, int min_pixels) {
  std::map<int, Region> by_id;
  for (int v = 0; v < labels.rows; ++v) {
    const int* row = labels.ptr<int>(v);
    for (int u = 0; u < labels.cols; ++u) {
      if (row[u] == none) continue;
      Region& r = by_id[row[u]];
      if (r.pixels == 0) {
        r.id = row[u];
        r.box = cv::Rect(u, v, 1, 1);
      } else {
        r.box |= cv::Rect(u, v, 1, 1);
      }
      ++r.pixels;
    }
  }
  std::vector<Region> out;
  for (const auto& [id, r] : by_id) {
    if (r.pixels >= min_pixels) out.push_back(r);
  }
  return out;
}

// CV_8UC1 mask of `id` within `roi`.
cv::Mat MaskOf(const cv::Mat& labels, int id, const cv::Rect& roi) {
  return labels(roi) == id;
}

// Mask pixels with a 4-neighbour outside the mask (or outside the ROI's
// image border).
cv::Mat Boundary(const cv::Mat& mask) {
  cv::Mat eroded;
  cv::erode(mask, eroded, cv::getStructuringElement(cv::MORPH_CROSS, {3, 3}),
            cv::Point(-1, -1), 1, cv::BORDER_CONSTANT, cv::Scalar(0));
  return mask & ~eroded;
}

// Pixels of boundary `a` within `tolerance` of a pixel of boundary `b`.
int WithinTolerance(const cv::Mat& a, const cv::Mat& b, int tolerance) {
  if (cv::countNonZero(b) == 0) return 0;
  cv::Mat distance;
  cv::distanceTransform(~b, distance, cv::DIST_L2, cv::DIST_MASK_PRECISE);
  return cv::countNonZero((distance <= tolerance) & a);
}

double F(double p, double r) {
  return p + r > 0.0 ? 2.0 * p * r / (p + r) : 0.0;
}

}  // namespace

int BoundaryTolerancePx(cv::Size size) {
  return static_cast<int>(std::ceil(
      0.003 * std::hypot(static_cast<double>(size.width), size.height)));
}

UoisScore ScoreUois(const cv::Mat& objects, const cv::Mat& segments,
                    int min_object_pixels) {
  UoisScore score;
  const std::vector<Region> gt = Regions(objects, 0, min_object_pixels);
  const std::vector<Region> pred = Regions(segments, -1, 1);
  score.objects = static_cast<int>(gt.size());
  score.segments = static_cast<int>(pred.size());
  if (gt.empty() && pred.empty()) {
    score.overlap_p = score.overlap_r = score.overlap_f = 1.0;
    score.boundary_p = score.boundary_r = score.boundary_f = 1.0;
    score.objects_075 = 1.0;
    return score;
  }
  // Pairwise intersections.
  std::map<int, int> gt_index, pred_index;
  for (size_t i = 0; i < gt.size(); ++i)
    gt_index[gt[i].id] = static_cast<int>(i);
  for (size_t j = 0; j < pred.size(); ++j)
    pred_index[pred[j].id] = static_cast<int>(j);
  std::vector<std::vector<int>> inter(gt.size(),
                                      std::vector<int>(pred.size(), 0));
  for (int v = 0; v < objects.rows; ++v) {
    const int* o = objects.ptr<int>(v);
    const int* s = segments.ptr<int>(v);
    for (int u = 0; u < objects.cols; ++u) {
      if (o[u] == 0 || s[u] < 0) continue;
      const auto gi = gt_index.find(o[u]);
      if (gi == gt_index.end()) continue;
      ++inter[gi->second][pred_index.at(s[u])];
    }
  }
  std::vector<std::vector<double>> f(gt.size(),
                                     std::vector<double>(pred.size(), 0.0));
  for (size_t i = 0; i < gt.size(); ++i) {
    for (size_t j = 0; j < pred.size(); ++j) {
      f[i][j] = 2.0 * inter[i][j] / (gt[i].pixels + pred[j].pixels);
    }
  }
  const std::vector<int> match = MaxWeightAssignment(f);

  long gt_pixels = 0, pred_pixels = 0, true_positive = 0;
  for (const Region& r : gt) gt_pixels += r.pixels;
  for (const Region& r : pred) pred_pixels += r.pixels;
  int above_075 = 0;
  const int tolerance = BoundaryTolerancePx(objects.size());
  long gt_boundary = 0, pred_boundary = 0, boundary_tp_p = 0, boundary_tp_r = 0;
  std::vector<bool> pred_matched(pred.size(), false);
  for (size_t i = 0; i < gt.size(); ++i) {
    const int j = match[i];
    if (j >= 0 && inter[i][j] > 0) {
      true_positive += inter[i][j];
      above_075 += f[i][j] > 0.75 ? 1 : 0;
      pred_matched[j] = true;
      const cv::Rect roi = ((gt[i].box | pred[j].box) +
                            cv::Size(2 * tolerance + 2, 2 * tolerance + 2) -
                            cv::Point(tolerance + 1, tolerance + 1)) &
                           cv::Rect(0, 0, objects.cols, objects.rows);
      const cv::Mat bo = Boundary(MaskOf(objects, gt[i].id, roi));
      const cv::Mat bs = Boundary(MaskOf(segments, pred[j].id, roi));
      gt_boundary += cv::countNonZero(bo);
      pred_boundary += cv::countNonZero(bs);
      boundary_tp_p += WithinTolerance(bs, bo, tolerance);
      boundary_tp_r += WithinTolerance(bo, bs, tolerance);
    } else {
      gt_boundary +=
          cv::countNonZero(Boundary(MaskOf(objects, gt[i].id, gt[i].box)));
    }
  }
  for (size_t j = 0; j < pred.size(); ++j) {
    if (!pred_matched[j]) {
      pred_boundary +=
          cv::countNonZero(Boundary(MaskOf(segments, pred[j].id, pred[j].box)));
    }
  }
  // No segments: nothing was claimed wrongly (P 1), nothing found (R 0).
  score.overlap_p =
      pred_pixels > 0 ? static_cast<double>(true_positive) / pred_pixels : 1.0;
  score.overlap_r =
      gt_pixels > 0 ? static_cast<double>(true_positive) / gt_pixels : 1.0;
  score.overlap_f = F(score.overlap_p, score.overlap_r);
  score.boundary_p = pred_boundary > 0
                         ? static_cast<double>(boundary_tp_p) / pred_boundary
                         : 1.0;
  score.boundary_r =
      gt_boundary > 0 ? static_cast<double>(boundary_tp_r) / gt_boundary : 1.0;
  score.boundary_f = F(score.boundary_p, score.boundary_r);
  score.objects_075 =
      gt.empty() ? 1.0 : static_cast<double>(above_075) / gt.size();
  return score;
}

}  // namespace fovea
