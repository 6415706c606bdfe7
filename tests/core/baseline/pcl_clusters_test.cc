#include "core/baseline/pcl_clusters.h"

#include <gtest/gtest.h>

#include "core/scene/support_plane.h"
#include "core/synth/synth_scene.h"

namespace fovea {
namespace {

struct Prepared {
  synth::SynthScene truth;
  OrganizedCloud cloud;
  TableScene table;
};

Prepared Render(const std::vector<synth::Primitive>& objects) {
  synth::SceneSpec spec;
  spec.camera_pose = synth::LookAt({0.0f, -0.7f, 0.7f}, {0.0f, 0.0f, 0.0f});
  spec.objects = objects;
  synth::NoiseOptions noise;
  noise.enabled = false;
  Prepared p;
  p.truth = synth::RenderScene(spec, noise, 1);
  p.cloud = *BuildOrganizedCloud(p.truth.frame.frame, {});
  const SupportPlane plane = *FindSupportPlane(p.cloud, {});
  p.table = PrepareTableScene(p.cloud, plane, {});
  return p;
}

synth::Primitive Box(float x, float y, float half) {
  synth::Primitive box;
  box.half_extents = {half, half, half};
  box.pose.translation() = Eigen::Vector3f(x, y, half);
  return box;
}

TEST(PclClustersTest, TwoSeparateBoxesGiveTwoPointsLargestFirst) {
  const Prepared p =
      Render({Box(-0.15f, 0.0f, 0.03f), Box(0.15f, 0.0f, 0.05f)});
  absl::StatusOr<std::vector<AttentionPoint>> points =
      DetectPclClusters(p.cloud, p.table, 10, {});
  ASSERT_TRUE(points.ok()) << points.status();
  ASSERT_EQ(points->size(), 2u);
  // The big box (object index 1, label 30) comes first.
  EXPECT_EQ(p.truth.frame.labels.at<int>((*points)[0].v, (*points)[0].u), 30);
  EXPECT_EQ(p.truth.frame.labels.at<int>((*points)[1].v, (*points)[1].u), 20);
  EXPECT_FLOAT_EQ((*points)[0].saliency, 1.0f);
  EXPECT_LT((*points)[1].saliency, 1.0f);
}

TEST(PclClustersTest, TouchingBoxesMergeIntoOneCluster) {
  // The peer's known weakness: objects in contact are one cluster.
  const Prepared p =
      Render({Box(-0.03f, 0.0f, 0.03f), Box(0.03f, 0.0f, 0.03f)});
  absl::StatusOr<std::vector<AttentionPoint>> points =
      DetectPclClusters(p.cloud, p.table, 10, {});
  ASSERT_TRUE(points.ok());
  EXPECT_EQ(points->size(), 1u);
}

TEST(PclClustersTest, NoCandidatesNoPointsAndBadOptionsNamed) {
  Prepared p = Render({Box(0.0f, 0.0f, 0.03f)});
  p.table.candidate.setTo(0);
  p.table.candidate_count = 0;
  EXPECT_TRUE(DetectPclClusters(p.cloud, p.table, 10, {})->empty());
  PclClustersOptions bad;
  bad.voxel_leaf = 0.0f;
  EXPECT_NE(Validate(bad).message().find("pcl_clusters.voxel_leaf"),
            std::string::npos);
}

}  // namespace
}  // namespace fovea
