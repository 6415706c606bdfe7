#include "core/eval/detection_metrics.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <set>

#include "core/frame/osd_pcd.h"

namespace fovea {
namespace {

// Centroid of an object's visible points and the range of their distances
// from it.
struct ObjectGeometry {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  int count = 0;
  Eigen::Vector3f centroid = Eigen::Vector3f::Zero();
  float r_min = 0.0f;
  float r_max = 0.0f;
};

std::map<int, ObjectGeometry> MeasureObjects(const cv::Mat& labels,
                                             const cv::Mat& xyz) {
  std::map<int, ObjectGeometry> objects;
  for (int v = 0; v < labels.rows; ++v) {
    const int* l = labels.ptr<int>(v);
    const cv::Vec3f* p = xyz.ptr<cv::Vec3f>(v);
    for (int u = 0; u < labels.cols; ++u) {
      const int id = ObjectId(l[u]);
      if (id == 0) continue;
      ObjectGeometry& g = objects[id];
      if (std::isnan(p[u][2])) continue;
      g.sum += Eigen::Vector3d(p[u][0], p[u][1], p[u][2]);
      ++g.count;
    }
  }
  for (auto& [id, g] : objects) {
    if (g.count > 0) g.centroid = (g.sum / g.count).cast<float>();
    g.r_min = std::numeric_limits<float>::max();
  }
  for (int v = 0; v < labels.rows; ++v) {
    const int* l = labels.ptr<int>(v);
    const cv::Vec3f* p = xyz.ptr<cv::Vec3f>(v);
    for (int u = 0; u < labels.cols; ++u) {
      const int id = ObjectId(l[u]);
      if (id == 0 || std::isnan(p[u][2])) continue;
      ObjectGeometry& g = objects[id];
      const float r =
          (Eigen::Vector3f(p[u][0], p[u][1], p[u][2]) - g.centroid).norm();
      g.r_min = std::min(g.r_min, r);
      g.r_max = std::max(g.r_max, r);
    }
  }
  return objects;
}

}  // namespace

DetectionScore ScoreAttentionPoints(const std::vector<AttentionPoint>& points,
                                    const cv::Mat& labels, const cv::Mat& xyz,
                                    int considered) {
  DetectionScore score;
  const std::map<int, ObjectGeometry> objects = MeasureObjects(labels, xyz);
  score.objects = static_cast<int>(objects.size());
  if (score.objects == 0) {
    score.distance_to_center = 0.0;
    score.distance_to_center_thesis = 0.0;
    return score;
  }
  // Object id under each returned point (0: table, nothing, outside).
  std::vector<int> hit_ids;
  hit_ids.reserve(points.size());
  for (const AttentionPoint& p : points) {
    const bool inside =
        p.u >= 0 && p.v >= 0 && p.u < labels.cols && p.v < labels.rows;
    hit_ids.push_back(inside ? ObjectId(labels.at<int>(p.v, p.u)) : 0);
  }
  // HR(N): distinct objects among the first N points / N.
  std::set<int> seen;
  int distinct = 0;
  for (int n = 1; n <= kHitRatioAtMax; ++n) {
    if (n <= static_cast<int>(hit_ids.size())) {
      const int id = hit_ids[n - 1];
      if (id != 0 && seen.insert(id).second) ++distinct;
    }
    score.hit_ratio_at[n - 1] = static_cast<double>(distinct) / n;
  }
  // HR and DC over the first K points.
  const int k = score.objects;
  seen.clear();
  double dc_sum = 0.0, dc_thesis_sum = 0.0;
  int on_object = 0;
  for (int i = 0; i < k; ++i) {
    const int id = i < static_cast<int>(hit_ids.size()) ? hit_ids[i] : 0;
    double thesis = -1.0;  // < 0: no 3D distance for this point
    double dc = 1.0;       // a miss
    if (id != 0) {
      const ObjectGeometry& g = objects.at(id);
      const cv::Vec3f& q = xyz.at<cv::Vec3f>(points[i].v, points[i].u);
      if (!std::isnan(q[2]) && g.count > 0 && g.r_max > 0.0f) {
        const float r = (Eigen::Vector3f(q[0], q[1], q[2]) - g.centroid).norm();
        const float span = g.r_max - g.r_min;
        thesis = std::min(r / g.r_max, 1.0f);
        if (seen.count(id) == 0) {
          dc = span > 0.0f ? std::clamp((r - g.r_min) / span, 0.0f, 1.0f) : 0.0;
        }
      }
      if (seen.insert(id).second) ++score.hits;
    }
    dc_sum += dc;
    if (thesis >= 0.0) {
      dc_thesis_sum += thesis;
      ++on_object;
    }
  }
  std::set<int> any;
  for (const int id : hit_ids) {
    if (id == 0) {
      ++score.off_object_points;
    } else if (!any.insert(id).second) {
      ++score.repeated_points;
    }
  }
  // HR over the first max(K, considered) points.
  for (int i = k; i < std::min<int>(std::max(k, considered), hit_ids.size());
       ++i) {
    if (hit_ids[i] != 0 && seen.insert(hit_ids[i]).second) ++score.hits;
  }
  score.hit_ratio = static_cast<double>(score.hits) / k;
  score.distance_to_center = dc_sum / k;
  if (on_object > 0)
    score.distance_to_center_thesis = dc_thesis_sum / on_object;
  return score;
}

}  // namespace fovea
