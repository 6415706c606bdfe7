#ifndef FOVEA_TESTS_CORE_SALIENCY_SCENE_FIXTURE_H_
#define FOVEA_TESTS_CORE_SALIENCY_SCENE_FIXTURE_H_

#include <gtest/gtest.h>

#include "core/frame/organized_cloud.h"
#include "core/scene/support_plane.h"
#include "core/scene/table_scene.h"
#include "tests/core/testing/scenes.h"

namespace fovea::testing {

// A rendered synthetic scene taken through cloud, plane and table scene.
struct PreparedScene {
  synth::SynthScene truth;
  OrganizedCloud cloud;
  SupportPlane plane;
  TableScene table;
  cv::Mat true_height;  // from the renderer's plane
};

inline PreparedScene Prepare(synth::SynthScene truth) {
  PreparedScene s;
  s.truth = std::move(truth);
  absl::StatusOr<OrganizedCloud> cloud =
      BuildOrganizedCloud(s.truth.frame.frame, {});
  EXPECT_TRUE(cloud.ok()) << cloud.status();
  s.cloud = *std::move(cloud);
  absl::StatusOr<SupportPlane> plane = FindSupportPlane(s.cloud, {});
  EXPECT_TRUE(plane.ok()) << plane.status();
  s.plane = *std::move(plane);
  s.table = PrepareTableScene(s.cloud, s.plane, {});
  s.true_height = HeightAboveTable(s.truth);
  return s;
}

}  // namespace fovea::testing

#endif  // FOVEA_TESTS_CORE_SALIENCY_SCENE_FIXTURE_H_
