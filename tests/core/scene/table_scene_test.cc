#include "core/scene/table_scene.h"

#include <gtest/gtest.h>

#include "core/scene/support_plane.h"
#include "core/synth/osd_crop.h"
#include "core/synth/stacked_bodies.h"
#include "tests/core/testing/scenes.h"

namespace fovea {
namespace {

using Eigen::Vector3f;

// A book lying flat (30 x 24 x 4 cm) whose front edge is 2 cm in front of
// the origin, a box standing on its back half (label 30), and, when
// `lone_box`, a box standing alone on the table far to the right and
// behind (label 40; `lift` metres above it). Camera as in BoxOnTable;
// Prepare crops the table as where books cover it.
synth::SceneSpec BookWithABoxOnIt(bool lone_box, float lift = 0.0f) {
  synth::SceneSpec spec;
  spec.camera_pose = synth::LookAt({0.0f, -0.75f, 0.75f}, {0.0f, 0.0f, 0.0f});
  spec.objects.push_back(synth::BoxPrimitive(Vector3f(0.0f, 0.10f, 0.02f),
                                             Vector3f(0.15f, 0.12f, 0.02f),
                                             Vector3f(0.2f, 0.3f, 0.7f)));
  spec.objects.push_back(synth::BoxPrimitive(Vector3f(0.0f, 0.16f, 0.09f),
                                             Vector3f(0.04f, 0.04f, 0.05f),
                                             Vector3f(0.8f, 0.3f, 0.2f)));
  if (lone_box) {
    spec.objects.push_back(synth::BoxPrimitive(
        Vector3f(0.40f, 0.25f, 0.05f + lift), Vector3f(0.04f, 0.04f, 0.05f),
        Vector3f(0.2f, 0.7f, 0.3f)));
  }
  return spec;
}

// Share of the pixels labelled `label` that `mask` holds.
double ShareIn(const cv::Mat& mask, const cv::Mat& labels, int label) {
  int all = 0, in = 0;
  for (int v = 0; v < labels.rows; ++v) {
    for (int u = 0; u < labels.cols; ++u) {
      if (labels.at<int>(v, u) != label) continue;
      ++all;
      in += mask.at<uint8_t>(v, u) != 0;
    }
  }
  return all > 0 ? static_cast<double>(in) / all : -1.0;
}

struct Prepared {
  synth::SynthScene scene;
  OrganizedCloud cloud;
  SupportPlane plane;
};

// `spec` rendered without noise, the table cropped beyond y = 2 cm (OSD's
// crop), its cloud and support.
Prepared Prepare(const synth::SceneSpec& spec) {
  synth::NoiseOptions noise;
  noise.enabled = false;
  Prepared p{synth::RenderScene(spec, noise, 1), {}, {}};
  synth::CropLikeOsd(spec, 0.02f, p.scene);
  absl::StatusOr<OrganizedCloud> cloud =
      BuildOrganizedCloud(p.scene.frame.frame, {});
  EXPECT_TRUE(cloud.ok());
  p.cloud = *std::move(cloud);
  absl::StatusOr<SupportPlane> plane = FindSupportPlane(p.cloud, {});
  EXPECT_TRUE(plane.ok()) << plane.status();
  if (plane.ok()) p.plane = *std::move(plane);
  return p;
}

TEST(TableSceneTest, WhatRestsOnABookBeyondTheVisibleTableIsInTheScene) {
  const Prepared p = Prepare(BookWithABoxOnIt(false));
  ASSERT_GT(p.plane.inlier_count, 0);
  TableSceneOptions without;
  without.rest_beyond_hull_m = 0.0f;
  const TableScene before = PrepareTableScene(p.cloud, p.plane, without);
  const TableScene after = PrepareTableScene(p.cloud, p.plane, {});
  const cv::Mat& labels = p.scene.frame.labels;
  // The visible table ends at the book's front half: the box on the book's
  // back half projects outside its hull, and without the rule it is not in
  // the scene at all (nor is most of the book).
  EXPECT_LT(ShareIn(before.region, labels, 30), 0.05);
  EXPECT_LT(ShareIn(before.region, labels, 20), 0.5);
  // With it, the book and the box on it are whole, and candidates.
  EXPECT_GT(ShareIn(after.region, labels, 20), 0.95);
  EXPECT_GT(ShareIn(after.region, labels, 30), 0.95);
  EXPECT_GT(ShareIn(after.candidate, labels, 30), 0.95);
  EXPECT_GT(ShareIn(after.standing, labels, 30), 0.95);
  EXPECT_EQ(after.candidate_count, cv::countNonZero(after.candidate));
}

TEST(TableSceneTest, ABoxOnTheHiddenTableIsInTheSceneAFloatingOneIsNot) {
  const Prepared p = Prepare(BookWithABoxOnIt(true));
  const cv::Mat& labels = p.scene.frame.labels;
  const TableScene scene = PrepareTableScene(p.cloud, p.plane, {});
  EXPECT_GT(ShareIn(scene.region, labels, 30), 0.95);
  // The lone box touches nothing in the scene, but its foot is at the
  // height of the table the crop hid: it stands on it (all but its lowest
  // centimetre, table-high, which beyond the hull is not in the scene).
  EXPECT_GT(ShareIn(scene.region, labels, 40), 0.9);
  EXPECT_GT(ShareIn(scene.candidate, labels, 40), 0.9);
  TableSceneOptions options;
  options.rest_on_hidden_table = false;
  EXPECT_EQ(
      ShareIn(PrepareTableScene(p.cloud, p.plane, options).region, labels, 40),
      0.0);
  // 12 cm up, it would not stand on the table (a shelf's box).
  options.rest_on_hidden_table = true;
  const Prepared floating = Prepare(BookWithABoxOnIt(true, 0.12f));
  EXPECT_EQ(
      ShareIn(PrepareTableScene(floating.cloud, floating.plane, options).region,
              floating.scene.frame.labels, 40),
      0.0);
}

TEST(TableSceneTest, ABoxWhoseFootAnotherHidesIsInTheScene) {
  // A tall box in front (label 20, 20 cm, standing across the crop line)
  // hides the lower part of a taller one 10 cm behind it (label 30, 25 cm,
  // beyond the crop): its lowest visible point is far above the table, but
  // what hides its foot is in the scene.
  synth::SceneSpec spec;
  spec.camera_pose = synth::LookAt({0.0f, -0.75f, 0.75f}, {0.0f, 0.0f, 0.0f});
  spec.objects.push_back(synth::BoxPrimitive(Vector3f(0.0f, 0.0f, 0.10f),
                                             Vector3f(0.08f, 0.06f, 0.10f),
                                             Vector3f(0.2f, 0.3f, 0.7f)));
  spec.objects.push_back(synth::BoxPrimitive(Vector3f(0.0f, 0.20f, 0.125f),
                                             Vector3f(0.05f, 0.04f, 0.125f),
                                             Vector3f(0.8f, 0.3f, 0.2f)));
  const Prepared p = Prepare(spec);
  const TableScene with = PrepareTableScene(p.cloud, p.plane, {});
  const cv::Mat& labels = p.scene.frame.labels;
  float lowest = 1.0f;
  for (int v = 0; v < labels.rows; ++v) {
    for (int u = 0; u < labels.cols; ++u) {
      if (labels.at<int>(v, u) == 30) {
        lowest = std::min(lowest, with.height.at<float>(v, u));
      }
    }
  }
  EXPECT_GT(lowest, 0.08f);  // no foot in sight
  EXPECT_GT(ShareIn(with.region, labels, 30), 0.95);
  TableSceneOptions options;
  options.rest_on_hidden_table = false;
  EXPECT_EQ(
      ShareIn(PrepareTableScene(p.cloud, p.plane, options).region, labels, 30),
      0.0);
}

TEST(TableSceneTest, ValidateNamesRestBeyondHull) {
  TableSceneOptions options;
  options.rest_beyond_hull_m = -0.1f;
  const absl::Status s = Validate(options);
  EXPECT_EQ(s.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(s.message().find("table_scene.rest_beyond_hull_m"),
            std::string::npos);
}

}  // namespace
}  // namespace fovea
