#include "core/frame/surface_edges.h"

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>
#include <set>

#include "core/frame/organized_cloud.h"
#include "core/synth/synth_scene.h"
#include "tests/core/testing/scenes.h"

namespace fovea {
namespace {

synth::Primitive Box(const Eigen::Vector3f& centre,
                     const Eigen::Vector3f& half_extents) {
  synth::Primitive box;
  box.shape = synth::Shape::kBox;
  box.half_extents = half_extents;
  box.pose.translation() = centre;
  return box;
}

synth::SynthScene Render(const std::vector<synth::Primitive>& objects) {
  synth::SceneSpec spec;
  spec.camera_pose = synth::LookAt({0.0f, -0.75f, 0.75f}, {0.0f, 0.0f, 0.0f});
  spec.objects = objects;
  synth::NoiseOptions noise;
  noise.enabled = false;
  return synth::RenderScene(spec, noise, 1);
}

OrganizedCloud CloudOf(const synth::SynthScene& scene) {
  absl::StatusOr<OrganizedCloud> cloud =
      BuildOrganizedCloud(scene.frame.frame, {});
  EXPECT_TRUE(cloud.ok()) << cloud.status();
  return cloud.ok() ? *std::move(cloud) : OrganizedCloud{};
}

// Labels (>= 20) that share a 4-connected component of object pixels that
// are not surface edges, per component; returns the largest number of
// labels any component holds.
int MostLabelsInOneComponent(const cv::Mat& labels, const cv::Mat& edges) {
  cv::Mat inside = (labels >= 20) & (edges == 0);
  cv::Mat components;
  const int n = cv::connectedComponents(inside, components, 4, CV_32S);
  std::vector<std::set<int>> seen(n);
  for (int v = 0; v < labels.rows; ++v) {
    for (int u = 0; u < labels.cols; ++u) {
      const int c = components.at<int>(v, u);
      if (c > 0) seen[c].insert(labels.at<int>(v, u));
    }
  }
  int most = 0;
  for (const std::set<int>& s : seen) most = std::max<int>(most, s.size());
  return most;
}

TEST(SurfaceEdgesTest, ABoxIsCutFromTheTableButNotAtItsConvexEdge) {
  const synth::SynthScene scene =
      testing::BoxOnTable(Eigen::Vector3f(0.06f, 0.06f, 0.06f));
  const OrganizedCloud cloud = CloudOf(scene);
  const cv::Mat edges = FindSurfaceEdges(cloud, {});
  const cv::Mat& labels = scene.frame.labels;
  // The upper half of the box's front face, up to the convex edge where it
  // meets the top face, is no edge: its comparisons reach across that
  // edge, where normals diverge. (Near the table the fold is concave, and
  // marked as wide as the normals are smoothed.)
  const cv::Mat height = testing::HeightAboveTable(scene);
  cv::Mat upper_front = (labels >= 20) & (height > 0.06f) & (height < 0.118f);
  cv::erode(upper_front, upper_front, cv::Mat::ones(1, 17, CV_8UC1));
  ASSERT_GT(cv::countNonZero(upper_front), 500);
  EXPECT_EQ(cv::countNonZero(upper_front & edges), 0);
  // Its outline is: the table meets it in a concave fold at the bottom and
  // lies 10+ cm behind it at the top. Every column through the box has an
  // edge pixel near both ends.
  int columns = 0, cut_top = 0, cut_bottom = 0;
  for (int u = 0; u < labels.cols; ++u) {
    int top = -1, bottom = -1;
    for (int v = 0; v < labels.rows; ++v) {
      if (labels.at<int>(v, u) < 20) continue;
      if (top < 0) top = v;
      bottom = v;
    }
    if (top < 0) continue;
    ++columns;
    auto edge_near = [&](int v0) {
      for (int v = std::max(0, v0 - 8); v <= std::min(labels.rows - 1, v0 + 8);
           ++v) {
        if (edges.at<uint8_t>(v, u)) return true;
      }
      return false;
    };
    cut_top += edge_near(top);
    cut_bottom += edge_near(bottom);
  }
  ASSERT_GT(columns, 40);
  EXPECT_GE(cut_top, columns * 95 / 100);
  EXPECT_GE(cut_bottom, columns * 90 / 100);
}

TEST(SurfaceEdgesTest, StackedAndOccludingBoxesFallApart) {
  // A small box on a large one (a concave fold between them), and a third
  // box in front of the large one (a depth step).
  const synth::SynthScene scene = Render({
      Box({0.0f, 0.05f, 0.06f}, {0.1f, 0.06f, 0.06f}),
      Box({0.0f, 0.05f, 0.16f}, {0.05f, 0.04f, 0.04f}),
      Box({0.04f, -0.12f, 0.04f}, {0.04f, 0.03f, 0.04f}),
  });
  const OrganizedCloud cloud = CloudOf(scene);
  const cv::Mat& labels = scene.frame.labels;
  std::set<int> visible;
  for (int v = 0; v < labels.rows; ++v) {
    for (int u = 0; u < labels.cols; ++u) {
      if (labels.at<int>(v, u) >= 20) visible.insert(labels.at<int>(v, u));
    }
  }
  ASSERT_EQ(visible.size(), 3u);
  EXPECT_EQ(MostLabelsInOneComponent(labels, FindSurfaceEdges(cloud, {})), 1);
  // Without the edges the three are one blob.
  cv::Mat none(labels.size(), CV_8UC1, cv::Scalar(0));
  EXPECT_EQ(MostLabelsInOneComponent(labels, none), 3);
  // Folds alone do not cut the occluder free; steps alone do not cut the
  // stacked box free.
  SurfaceEdgeOptions steps_only;
  steps_only.concave_curvature = 0.0f;
  SurfaceEdgeOptions folds_only;
  folds_only.depth_jump_fraction = 0.0f;
  EXPECT_GT(
      MostLabelsInOneComponent(labels, FindSurfaceEdges(cloud, steps_only)), 1);
  EXPECT_GT(
      MostLabelsInOneComponent(labels, FindSurfaceEdges(cloud, folds_only)), 1);
}

// Share of `mask` that is surface edge.
double EdgeShare(const cv::Mat& mask, const cv::Mat& edges) {
  return static_cast<double>(cv::countNonZero(mask & edges)) /
         std::max(1, cv::countNonZero(mask));
}

TEST(SurfaceEdgesTest, ABowlsInsideIsOneSurfaceButAStackedBoxIsCut) {
  // A 7 cm bowl, 5 cm deep, its floor 15 mm up: its inside bends by
  // 1 / 6.5 cm = 15 / m, below the 20 / m a crease needs; the fold between
  // a box and the box it stands on is sharp.
  synth::Primitive bowl;
  bowl.shape = synth::Shape::kBowl;
  bowl.radius = 0.07f;
  bowl.half_extents = Eigen::Vector3f(0.07f, 0.07f, 0.025f);
  bowl.thickness = 0.005f;
  bowl.floor_height = 0.015f;
  bowl.pose.translation() = Eigen::Vector3f(-0.1f, 0.0f, 0.025f);
  const synth::SynthScene scene = Render({
      bowl,
      Box({0.12f, 0.0f, 0.05f}, {0.06f, 0.06f, 0.05f}),
      Box({0.12f, 0.0f, 0.13f}, {0.03f, 0.03f, 0.03f}),
  });
  const OrganizedCloud cloud = CloudOf(scene);
  const cv::Mat& labels = scene.frame.labels;
  // The bowl's inside: its pixels below the rim, away from its outline
  // and from the rim's occluding edge (marked radius_px wide).
  cv::Mat inside = (labels == 20) & (testing::HeightAboveTable(scene) < 0.045f);
  cv::erode(inside, inside, cv::Mat::ones(15, 15, CV_8UC1));
  ASSERT_GT(cv::countNonZero(inside), 500);
  const cv::Mat edges = FindSurfaceEdges(cloud, {});
  EXPECT_LT(EdgeShare(inside, edges), 0.1);
  // Any fold is a crease without the sharpness test: most of it.
  SurfaceEdgeOptions any_fold;
  any_fold.concave_min_curvature = 0.0f;
  EXPECT_GT(EdgeShare(inside, FindSurfaceEdges(cloud, any_fold)), 0.3);
  // The stacked box still comes off the one below.
  cv::Mat boxes = labels.clone();
  boxes.setTo(0, labels == 20);
  EXPECT_EQ(MostLabelsInOneComponent(boxes, edges), 1);
}

TEST(SurfaceEdgesTest, AFlatTableHasNoEdges) {
  const RgbdFrame frame = testing::PlaneFrame({0.0f, -0.6f, -0.8f}, 0.9f);
  absl::StatusOr<OrganizedCloud> cloud = BuildOrganizedCloud(frame, {});
  ASSERT_TRUE(cloud.ok()) << cloud.status();
  EXPECT_EQ(cv::countNonZero(FindSurfaceEdges(*cloud, {})), 0);
}

TEST(SurfaceEdgesTest, RejectsBadOptionsNamingTheField) {
  SurfaceEdgeOptions o;
  o.radius_px = 0;
  EXPECT_NE(Validate(o).message().find("radius_px"), std::string::npos);
  o = {};
  o.depth_jump_fraction = -0.1f;
  EXPECT_NE(Validate(o).message().find("depth_jump_fraction"),
            std::string::npos);
  o = {};
  o.concave_curvature = std::numeric_limits<float>::quiet_NaN();
  EXPECT_NE(Validate(o).message().find("concave_curvature"), std::string::npos);
  o = {};
  o.concave_min_curvature = -1.0f;
  EXPECT_NE(Validate(o).message().find("concave_min_curvature"),
            std::string::npos);
  EXPECT_TRUE(Validate(SurfaceEdgeOptions{}).ok());
}

}  // namespace
}  // namespace fovea
