#ifndef FOVEA_CORE_SCENE_HULL_CANDIDATES_H_
#define FOVEA_CORE_SCENE_HULL_CANDIDATES_H_

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <vector>

namespace fovea {

// The points of a 2D set that can be vertices of its convex hull (Akl and
// Toussaint 1978), in their order: the set's extreme points in 8
// directions 45 degrees apart span a convex polygon inside the hull, and a
// point strictly inside that polygon (by a margin above float rounding) is
// strictly inside the hull. cv::convexHull and cv::minAreaRect of the
// candidates are those of all the points; on an object's or a table's
// footprint, the candidates are a small share of them. Fewer than 3
// distinct extremes: every point.
std::vector<cv::Point2f> HullCandidates(
    const std::vector<Eigen::Vector2f>& points);

}  // namespace fovea

#endif  // FOVEA_CORE_SCENE_HULL_CANDIDATES_H_
