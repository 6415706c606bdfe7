#include "core/scene/hull_candidates.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <random>
#include <vector>

namespace fovea {
namespace {

std::vector<cv::Point2f> AsCv(const std::vector<Eigen::Vector2f>& points) {
  std::vector<cv::Point2f> out;
  for (const Eigen::Vector2f& p : points) out.emplace_back(p.x(), p.y());
  return out;
}

TEST(HullCandidatesTest, PointsInsideTheExtremesOctagonAreLeftOut) {
  // A square's corners and edge midpoints are extremes or on the hull;
  // the centre and a point near it are strictly inside: left out.
  const std::vector<Eigen::Vector2f> points = {
      {0, 0}, {1, 1}, {2, 0}, {2, 2}, {0.9f, 1.1f}, {0, 2}, {1, 0}, {0, 1}};
  const std::vector<cv::Point2f> kept = HullCandidates(points);
  EXPECT_EQ(kept.size(), 6u);
  for (const cv::Point2f& p : kept) {
    EXPECT_FALSE(p == cv::Point2f(1, 1));
    EXPECT_FALSE(p == cv::Point2f(0.9f, 1.1f));
  }
}

TEST(HullCandidatesTest, FewOrDegeneratePointsAreAllKept) {
  EXPECT_TRUE(HullCandidates({}).empty());
  EXPECT_EQ(HullCandidates({{1, 2}}).size(), 1u);
  // On one line: no polygon with an inside.
  const std::vector<Eigen::Vector2f> line = {{0, 0}, {1, 1}, {2, 2}, {3, 3}};
  EXPECT_EQ(HullCandidates(line).size(), line.size());
}

TEST(HullCandidatesTest, GiveTheHullAndMinAreaRectOfAllThePoints) {
  // Footprints like an object's: noisy filled ellipses and rotated
  // rectangles of a few hundred to 20,000 points in metres, some on a grid
  // (collinear edges, repeated points).
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  std::normal_distribution<float> noise(0.0f, 0.001f);
  for (int k = 0; k < 60; ++k) {
    SCOPED_TRACE(k);
    const int n = 200 + static_cast<int>(unit(rng) * 20000);
    const float a = 0.02f + 0.1f * unit(rng), b = 0.02f + 0.1f * unit(rng);
    const float turn = static_cast<float>(M_PI) * unit(rng);
    const Eigen::Vector2f centre(unit(rng) - 0.5f, 1.0f + unit(rng));
    std::vector<Eigen::Vector2f> points;
    for (int i = 0; i < n; ++i) {
      Eigen::Vector2f p;
      if (k % 3 == 0) {  // a grid: collinear edges
        p = {std::round(unit(rng) * 40) / 40 * a,
             std::round(unit(rng) * 40) / 40 * b};
      } else if (k % 3 == 1) {  // a rectangle
        p = {(unit(rng) - 0.5f) * a, (unit(rng) - 0.5f) * b};
      } else {  // an ellipse
        const float r = std::sqrt(unit(rng));
        const float t = 2.0f * static_cast<float>(M_PI) * unit(rng);
        p = {r * a * std::cos(t), r * b * std::sin(t)};
      }
      p += Eigen::Vector2f(noise(rng), noise(rng));
      points.push_back(centre + Eigen::Rotation2Df(turn) * p);
    }
    const std::vector<cv::Point2f> all = AsCv(points);
    const std::vector<cv::Point2f> kept = HullCandidates(points);
    EXPECT_LT(kept.size(), all.size());
    std::vector<cv::Point2f> hull_all, hull_kept;
    cv::convexHull(all, hull_all);
    cv::convexHull(kept, hull_kept);
    EXPECT_EQ(hull_kept, hull_all);
    const cv::RotatedRect rect_all = cv::minAreaRect(all);
    const cv::RotatedRect rect_kept = cv::minAreaRect(kept);
    EXPECT_EQ(rect_kept.center, rect_all.center);
    EXPECT_EQ(rect_kept.size, rect_all.size);
    EXPECT_EQ(rect_kept.angle, rect_all.angle);
  }
}

}  // namespace
}  // namespace fovea
