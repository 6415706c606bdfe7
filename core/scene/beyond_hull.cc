// What rests on the table beyond the hull of the table the camera sees
// (TableSceneOptions::rest_beyond_hull_m, rest_on_hidden_table): grown
// from the candidates, or standing on a table the camera does not see.

#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "core/base/parallel.h"
#include "core/scene/table_scene_internal.h"

namespace fovea::table_scene_internal {
namespace {

// Distance of q outside the convex polygon `hull` (counter-clockwise),
// metres: 0 inside, else the distance to its nearest edge.
float DistanceOutsideHull(const std::vector<Eigen::Vector2f>& hull,
                          const Eigen::Vector2f& q) {
  bool outside = false;
  float nearest = std::numeric_limits<float>::infinity();
  for (size_t i = 0; i < hull.size(); ++i) {
    const Eigen::Vector2f& a = hull[i];
    const Eigen::Vector2f edge = hull[(i + 1) % hull.size()] - a;
    const Eigen::Vector2f aq = q - a;
    if (edge.x() * aq.y() - edge.y() * aq.x() < 0.0f) outside = true;
    const float len2 = edge.squaredNorm();
    const float t =
        len2 > 0.0f ? std::clamp(edge.dot(aq) / len2, 0.0f, 1.0f) : 0.0f;
    nearest = std::min(nearest, (aq - t * edge).norm());
  }
  return outside ? nearest : 0.0f;
}

// Depth may change by this much between neighbouring pixels of one surface
// that rests on the table beyond its hull: max(kRestDepthStep, kRestDepth
// Fraction z), metres; the Kinect's disparity steps at 1.5 m are 7 mm, and
// a surface seen at a grazing angle changes faster.
constexpr float kRestDepthStep = 0.02f;
constexpr float kRestDepthFraction = 0.03f;
float RestStep(float z) {
  return std::max(kRestDepthStep, kRestDepthFraction * z);
}
// The candidates the fill starts from are those left by an opening of this
// radius, pixels: an object's face keeps its inside, a speck does not.
constexpr int kRestSeedOpening = 2;
// A part beyond the hull stands on the hidden table when its lowest point
// is at most this above the height where the table ends, metres (a box's
// foot seen over what stands in front of it); and counts at all from this
// many pixels at 640 x 480 (scaled with the pixel count).
constexpr float kRestContactGap = 0.02f;
constexpr int kRestMinPixels = 60;
// A table top's normals are within 25 degrees of the support's (as the
// support's inliers, SupportPlaneOptions::max_normal_angle_deg).
constexpr float kTableTopCos = 0.906f;
// A part's foot: its points within this of its lowest, metres.
constexpr float kFootBand = 0.01f;

// Whether the point at (u, v), not yet in the scene, may rest on the table
// beyond its hull: above the table as a candidate, within reach of the
// hull, on no structure.
bool MayRestBeyondHull(const OrganizedCloud& cloud, const SupportPlane& plane,
                       const TableSceneOptions& o, const TableScene& scene,
                       int u, int v) {
  const cv::Vec3f& p = cloud.xyz.at<cv::Vec3f>(v, u);
  const float z = p[2];
  if (std::isnan(z) || scene.region.at<uint8_t>(v, u) != 0) return false;
  const float hgt = scene.height.at<float>(v, u);
  const float min_height = TableNoiseBand(z, o);
  if (!(hgt > min_height && hgt <= o.max_object_height)) return false;
  const Eigen::Vector3f q(p[0], p[1], p[2]);
  if (DistanceOutsideHull(plane.hull, plane.ToPlane(q)) >
      o.rest_beyond_hull_m) {
    return false;
  }
  return scene.structures.empty() ||
         !OnStructure(scene.structures, q, cloud.normals.at<cv::Vec3f>(v, u),
                      o);
}

// Whether the pixel shows a table top: the support's inliers, or a surface
// level with the table (within its noise band) facing up as it does.
bool IsTableTop(const OrganizedCloud& cloud, const SupportPlane& plane,
                const TableSceneOptions& o, const TableScene& scene,
                cv::Point q) {
  // The support's inliers are at the frame's resolution; a pyramid level's
  // cloud (ChannelComputer) is smaller, and there only the level test below
  // applies.
  if (plane.inliers.size() == cloud.xyz.size() &&
      plane.inliers.at<uint8_t>(q) != 0) {
    return true;
  }
  const float z = cloud.xyz.at<cv::Vec3f>(q)[2];
  const float band = TableNoiseBand(z, o);
  const cv::Vec3f& n = cloud.normals.at<cv::Vec3f>(q);
  return std::abs(scene.height.at<float>(q)) <= band &&
         std::abs(plane.normal.x() * n[0] + plane.normal.y() * n[1] +
                  plane.normal.z() * n[2]) >= kTableTopCos;
}

// Whether the pixel, not yet in the scene and within reach of the hull, is
// level with the table (within its noise band) but no table top: the foot
// of something standing on the table, or of a wall rising from its edge.
// The fill of AddStandingOnHiddenTable follows such points, so that a
// wall's specks above the band are one part with the wall.
bool AtFootLevel(const OrganizedCloud& cloud, const SupportPlane& plane,
                 const TableSceneOptions& o, const TableScene& scene,
                 cv::Point q) {
  const cv::Vec3f& p = cloud.xyz.at<cv::Vec3f>(q);
  if (std::isnan(p[2]) || scene.region.at<uint8_t>(q) != 0) return false;
  const float band = TableNoiseBand(p[2], o);
  if (!(std::abs(scene.height.at<float>(q)) <= band)) return false;
  if (IsTableTop(cloud, plane, o, scene, q)) return false;
  return DistanceOutsideHull(
             plane.hull, plane.ToPlane(Eigen::Vector3f(p[0], p[1], p[2]))) <=
         o.rest_beyond_hull_m;
}

// What each pixel is to the search beyond the hull, computed once: kAbove
// where it may rest beyond the hull (MayRestBeyondHull), kFoot where it is
// at the table's level there (AtFootLevel), else kNotResting. CV_8UC1.
enum RestKind : uint8_t { kNotResting = 0, kAbove = 1, kFoot = 2 };
cv::Mat ClassifyBeyondHull(const OrganizedCloud& cloud,
                           const SupportPlane& plane,
                           const TableSceneOptions& options,
                           const TableScene& scene) {
  cv::Mat kind(cloud.height(), cloud.width(), CV_8UC1, cv::Scalar(0));
  ParallelForRanges(cloud.height(), [&](int begin, int end) {
    for (int v = begin; v < end; ++v) {
      uint8_t* k = kind.ptr<uint8_t>(v);
      for (int u = 0; u < cloud.width(); ++u) {
        if (MayRestBeyondHull(cloud, plane, options, scene, u, v)) {
          k[u] = kAbove;
        } else if (AtFootLevel(cloud, plane, options, scene, cv::Point(u, v))) {
          k[u] = kFoot;
        }
      }
    }
  });
  return kind;
}

// Whether `part` (a depth-connected part of the points that may rest beyond
// the hull) is bounded as an object on a hidden table is: no pixel
// 4-adjacent to it shows a table top (the support's inliers, or a surface
// level with the table, within its noise band, facing up as it does): what
// borders a visible table outside its hull stands behind the table's edge
// or on another table; and the part does not go on, without a jump in
// depth, beyond the reach of the hull or above max_object_height (a wall
// whose depth noise brings specks of it within reach).
bool BoundedAsAnObject(const OrganizedCloud& cloud, const SupportPlane& plane,
                       const TableSceneOptions& o, const TableScene& scene,
                       const std::vector<cv::Point>& part) {
  const int du[4] = {1, -1, 0, 0}, dv[4] = {0, 0, 1, -1};
  for (const cv::Point& q : part) {
    const float zq = cloud.xyz.at<cv::Vec3f>(q)[2];
    const float step = RestStep(zq);
    for (int k = 0; k < 4; ++k) {
      const int u = q.x + du[k], v = q.y + dv[k];
      if (u < 0 || v < 0 || u >= cloud.width() || v >= cloud.height()) {
        continue;
      }
      const cv::Vec3f& p = cloud.xyz.at<cv::Vec3f>(v, u);
      if (std::isnan(p[2])) continue;
      if (IsTableTop(cloud, plane, o, scene, cv::Point(u, v))) return false;
      const float hgt = scene.height.at<float>(v, u);
      const float band = TableNoiseBand(p[2], o);
      if (!(std::abs(p[2] - zq) <= step) ||
          scene.region.at<uint8_t>(v, u) != 0) {
        continue;
      }
      if (hgt > o.max_object_height ||
          (hgt > band &&
           DistanceOutsideHull(
               plane.hull, plane.ToPlane(Eigen::Vector3f(p[0], p[1], p[2]))) >
               o.rest_beyond_hull_m)) {
        return false;
      }
    }
  }
  return true;
}

// Whether, of `part`'s lowest pixels (within kFootBand of `lowest`) that
// lie on a jump in depth, most border something of the scene (its region,
// or `grown` beyond the hull) nearer to the camera: the part's foot is
// hidden behind what stands in front of it (a box behind an open box, an
// object behind a row of books). Pixels beside no depth (OSD's crop) do
// not count either way.
bool FootHiddenByTheScene(const OrganizedCloud& cloud, const TableScene& scene,
                          const cv::Mat& grown,
                          const std::vector<cv::Point>& part, float lowest) {
  const int du[4] = {1, -1, 0, 0}, dv[4] = {0, 0, 1, -1};
  int edges = 0, hidden = 0;
  for (const cv::Point& q : part) {
    if (scene.height.at<float>(q) > lowest + kFootBand) continue;
    const float z = cloud.xyz.at<cv::Vec3f>(q)[2];
    const float step = RestStep(z);
    bool edge = false, behind = false;
    for (int k = 0; k < 4; ++k) {
      const int u = q.x + du[k], v = q.y + dv[k];
      if (u < 0 || v < 0 || u >= cloud.width() || v >= cloud.height()) {
        continue;
      }
      const float zn = cloud.xyz.at<cv::Vec3f>(v, u)[2];
      if (std::isnan(zn) || std::abs(zn - z) <= step) continue;
      edge = true;
      behind = behind || (zn < z && (scene.region.at<uint8_t>(v, u) != 0 ||
                                     grown.at<uint8_t>(v, u) != 0));
    }
    edges += edge;
    hidden += behind;
  }
  return hidden > 0 && 2 * hidden > edges;
}

// Whether `part` (pixels of points that may rest beyond the hull, and their
// feet) stands on the table: its lowest point near the table, no wider than
// an object, and bounded as an object (BoundedAsAnObject).
bool StandsOnTheTable(const OrganizedCloud& cloud, const SupportPlane& plane,
                      const TableSceneOptions& o, const TableScene& scene,
                      const cv::Mat& grown,
                      const std::vector<cv::Point>& part) {
  const float inf = std::numeric_limits<float>::infinity();
  float lowest = inf, contact = inf;
  Eigen::Vector2f lo(inf, inf), hi(-inf, -inf);
  for (const cv::Point& q : part) {
    const cv::Vec3f& p = cloud.xyz.at<cv::Vec3f>(q);
    const float hgt = scene.height.at<float>(q);
    if (hgt < lowest) {
      lowest = hgt;
      contact = TableNoiseBand(p[2], o) + kRestContactGap;
    }
    const Eigen::Vector2f xy = plane.ToPlane(Eigen::Vector3f(p[0], p[1], p[2]));
    lo = lo.cwiseMin(xy);
    hi = hi.cwiseMax(xy);
  }
  if (!((hi - lo).norm() <= o.max_resting_size_m)) return false;
  if (!(lowest <= contact) &&
      !FootHiddenByTheScene(cloud, scene, grown, part, lowest)) {
    return false;
  }
  return BoundedAsAnObject(cloud, plane, o, scene, part);
}

// The points beyond the hull that rest on the table through the candidates
// (TableSceneOptions::rest_beyond_hull_m): the parts of them connected,
// over 4-neighbours without a depth jump and through standing points (an
// object's outer 2 cm, which are not taken), to a seed. Seeds are the
// candidates' interiors (the mask opened by kRestSeedOpening px),
// hull_margin inside the hull: not every standing point, since a wall
// rising at the table's edge stands on the hull's boundary, and not the
// specks of such a wall that its depth noise carries inside the hull. The
// fill starts from the points beyond the hull, so that it costs what lies
// there, not what stands on the table. CV_8UC1, 255 on the points taken.
cv::Mat GrowBeyondHull(const OrganizedCloud& cloud, const TableScene& scene,
                       const cv::Mat& kind) {
  const int w = cloud.width(), h = cloud.height();
  cv::Mat grown(h, w, CV_8UC1, cv::Scalar(0));
  cv::Mat seeds;
  cv::morphologyEx(scene.candidate, seeds, cv::MORPH_OPEN,
                   cv::getStructuringElement(
                       cv::MORPH_RECT, cv::Size(2 * kRestSeedOpening + 1,
                                                2 * kRestSeedOpening + 1)));
  cv::Mat visited(h, w, CV_8UC1, cv::Scalar(0));
  const int du[4] = {1, -1, 0, 0}, dv[4] = {0, 0, 1, -1};
  std::vector<cv::Point> part, frontier;
  for (int v0 = 0; v0 < h; ++v0) {
    for (int u0 = 0; u0 < w; ++u0) {
      if (visited.at<uint8_t>(v0, u0) != 0) continue;
      if (kind.at<uint8_t>(v0, u0) != kAbove) continue;
      visited.at<uint8_t>(v0, u0) = 255;
      part.assign(1, cv::Point(u0, v0));
      frontier.assign(1, cv::Point(u0, v0));
      bool seeded = false;
      while (!frontier.empty()) {
        const cv::Point at = frontier.back();
        frontier.pop_back();
        const float z = cloud.xyz.at<cv::Vec3f>(at)[2];
        for (int k = 0; k < 4; ++k) {
          const int u = at.x + du[k], v = at.y + dv[k];
          if (u < 0 || v < 0 || u >= w || v >= h) continue;
          if (visited.at<uint8_t>(v, u) != 0) continue;
          const float zq = cloud.xyz.at<cv::Vec3f>(v, u)[2];
          if (!(std::abs(zq - z) <= RestStep(std::max(z, zq)))) {
            continue;
          }
          const bool standing = scene.standing.at<uint8_t>(v, u) != 0;
          if (!standing && kind.at<uint8_t>(v, u) != kAbove) continue;
          visited.at<uint8_t>(v, u) = 255;
          if (standing) {
            seeded = seeded || seeds.at<uint8_t>(v, u) != 0;
          } else {
            part.emplace_back(u, v);
          }
          frontier.emplace_back(u, v);
        }
      }
      if (!seeded) continue;
      for (const cv::Point& q : part) grown.at<uint8_t>(q) = 255;
    }
  }
  return grown;
}

// Adds to `grown` the parts beyond the hull that stand on the table
// directly where the camera does not see it (TableSceneOptions::
// rest_on_hidden_table): depth-connected parts of the points that may rest
// beyond the hull, not yet grown, whose lowest point comes within
// max(min_object_height, min_height_sigmas sigma) + kRestContactGap of the
// table, at most max_resting_size_m across in the plane (a wall's foot
// above the table's back edge runs along all of it) and of at least
// kRestMinPixels pixels at 640 columns.
void AddStandingOnHiddenTable(const OrganizedCloud& cloud,
                              const SupportPlane& plane,
                              const TableSceneOptions& options,
                              const TableScene& scene, const cv::Mat& kind,
                              cv::Mat& grown) {
  const int w = cloud.width(), h = cloud.height();
  const int min_pixels = std::max(1, kRestMinPixels * w / 640 * h / 480);
  cv::Mat visited = grown.clone();
  const int du[4] = {1, -1, 0, 0}, dv[4] = {0, 0, 1, -1};
  // `part`: what the fill reached, `above` of it the points above the
  // table's noise band (the feet at its level are followed, not taken).
  std::vector<cv::Point> part, above, frontier;
  for (int v0 = 0; v0 < h; ++v0) {
    for (int u0 = 0; u0 < w; ++u0) {
      // Only a point above the band starts a part; the feet it reaches
      // stay free for the fill until then.
      if (visited.at<uint8_t>(v0, u0) != 0) continue;
      if (kind.at<uint8_t>(v0, u0) != kAbove) continue;
      visited.at<uint8_t>(v0, u0) = 255;
      part.assign(1, cv::Point(u0, v0));
      above.assign(1, cv::Point(u0, v0));
      frontier.assign(1, cv::Point(u0, v0));
      while (!frontier.empty()) {
        const cv::Point at = frontier.back();
        frontier.pop_back();
        const float z = cloud.xyz.at<cv::Vec3f>(at.y, at.x)[2];
        const float step = RestStep(z);
        for (int k = 0; k < 4; ++k) {
          const int u = at.x + du[k], v = at.y + dv[k];
          if (u < 0 || v < 0 || u >= w || v >= h) continue;
          if (visited.at<uint8_t>(v, u) != 0) continue;
          if (!(std::abs(cloud.xyz.at<cv::Vec3f>(v, u)[2] - z) <= step)) {
            continue;
          }
          const bool may_rest = kind.at<uint8_t>(v, u) == kAbove;
          if (!may_rest && kind.at<uint8_t>(v, u) != kFoot) continue;
          visited.at<uint8_t>(v, u) = 255;
          part.emplace_back(u, v);
          if (may_rest) above.emplace_back(u, v);
          frontier.emplace_back(u, v);
        }
      }
      if (static_cast<int>(above.size()) < min_pixels) continue;
      if (StandsOnTheTable(cloud, plane, options, scene, grown, part)) {
        for (const cv::Point& q : above) grown.at<uint8_t>(q) = 255;
      }
    }
  }
}

// Removes from `grown` its connected parts wider in the plane than
// max_resting_size_m (their bounding box's diagonal), and those of fewer
// than kRestMinPixels pixels (at 640 x 480): a wall whose foot the
// candidates reach (a table pushed against it) runs along the table, and
// the specks of one that its depth noise carries inside the hull, which
// the fill reaches, grow only to specks.
void DropPartsUnlikeObjects(const OrganizedCloud& cloud,
                            const SupportPlane& plane,
                            const TableSceneOptions& options, cv::Mat& grown) {
  cv::Mat parts;
  const int count = cv::connectedComponents(grown, parts, 8, CV_32S);
  if (count <= 1) return;
  const int min_pixels =
      std::max(1, kRestMinPixels * cloud.width() / 640 * cloud.height() / 480);
  std::vector<int> pixels(count, 0);
  const float inf = std::numeric_limits<float>::infinity();
  std::vector<Eigen::Vector2f> lo(count, Eigen::Vector2f(inf, inf));
  std::vector<Eigen::Vector2f> hi(count, Eigen::Vector2f(-inf, -inf));
  for (int v = 0; v < grown.rows; ++v) {
    const int* part = parts.ptr<int>(v);
    const cv::Vec3f* p = cloud.xyz.ptr<cv::Vec3f>(v);
    for (int u = 0; u < grown.cols; ++u) {
      if (part[u] == 0) continue;
      const Eigen::Vector2f q =
          plane.ToPlane(Eigen::Vector3f(p[u][0], p[u][1], p[u][2]));
      lo[part[u]] = lo[part[u]].cwiseMin(q);
      hi[part[u]] = hi[part[u]].cwiseMax(q);
      ++pixels[part[u]];
    }
  }
  std::vector<uint8_t> wide(count, 0);
  for (int k = 1; k < count; ++k) {
    wide[k] = (hi[k] - lo[k]).norm() > options.max_resting_size_m ||
              pixels[k] < min_pixels;
  }
  for (int v = 0; v < grown.rows; ++v) {
    const int* part = parts.ptr<int>(v);
    uint8_t* g = grown.ptr<uint8_t>(v);
    for (int u = 0; u < grown.cols; ++u) {
      if (wide[part[u]]) g[u] = 0;
    }
  }
}

}  // namespace

void AddWhatRestsBeyondHull(const OrganizedCloud& cloud,
                            const SupportPlane& plane,
                            const TableSceneOptions& options,
                            TableScene& scene) {
  if (options.rest_beyond_hull_m <= 0.0f || plane.hull.size() < 3) return;
  const cv::Mat kind = ClassifyBeyondHull(cloud, plane, options, scene);
  cv::Mat grown = GrowBeyondHull(cloud, scene, kind);
  DropPartsUnlikeObjects(cloud, plane, options, grown);
  if (options.rest_on_hidden_table) {
    AddStandingOnHiddenTable(cloud, plane, options, scene, kind, grown);
  }
  scene.region.setTo(cv::Scalar(255), grown);
  scene.standing.setTo(cv::Scalar(255), grown);
  scene.candidate.setTo(cv::Scalar(255), grown);
  scene.candidate_count = cv::countNonZero(scene.candidate);
}

}  // namespace fovea::table_scene_internal
