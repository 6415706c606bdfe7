// A dark object whose depth the sensor returns at scattered pixels only
// comes back whole: SegmentIncremental, with the shipped models, on a
// synthetic table seen by a Kinect (core/frame/dropout_fill.h).

#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/core.hpp>
#include <vector>

#include "core/pipeline/incremental.h"
#include "core/synth/synth_scene.h"
#include "tests/core/testing/models.h"
#include "tests/core/testing/sinks.h"

namespace fovea {
namespace {

// A black box and a black cylinder on a table, 0.9 m from a Kinect.
synth::SynthScene DarkObjects() {
  synth::SceneSpec spec;
  spec.camera_pose = synth::LookAt({0.0f, -0.6f, 0.65f}, {0.0f, 0.0f, 0.0f});
  synth::Primitive box;
  box.half_extents = {0.07f, 0.05f, 0.05f};
  box.pose.translation() = Eigen::Vector3f(-0.1f, 0.0f, 0.05f);
  box.rgb = Eigen::Vector3f(0.05f, 0.05f, 0.06f);
  synth::Primitive can = box;
  can.shape = synth::Shape::kCylinder;
  can.half_extents = {0.04f, 0.04f, 0.06f};
  can.pose.translation() = Eigen::Vector3f(0.12f, 0.02f, 0.06f);
  spec.objects = {box, can};
  return synth::RenderScene(spec, synth::KinectV1Noise(), 3);
}

struct OnObject {
  int masks = 0;        // masks lying mostly on the object
  double best_f = 0.0;  // the best F of any mask against it
};

OnObject Score(const std::vector<cv::Mat>& masks, const cv::Mat& object) {
  OnObject out;
  const double size = cv::countNonZero(object);
  for (const cv::Mat& mask : masks) {
    const double both = cv::countNonZero(mask & object);
    const double pixels = cv::countNonZero(mask);
    out.masks += both > 0.5 * pixels;
    out.best_f = std::max(out.best_f, 2.0 * both / (size + pixels));
  }
  return out;
}

std::vector<cv::Mat> Masks(const RgbdFrame& frame,
                           const IncrementalOptions& options) {
  std::vector<cv::Mat> masks;
  const absl::Status status =
      RunSegmentIncremental(frame, options, &*testing::ShippedModels()->inc,
                            testing::CollectMasks(masks))
          .status();
  EXPECT_TRUE(status.ok()) << status;
  return masks;
}

TEST(DarkObjectsTest, EachComesBackAsOneMask) {
  ASSERT_NE(testing::ShippedModels(), nullptr)
      << "the shipped models do not load";
  const synth::SynthScene scene = DarkObjects();
  cv::Mat no_depth(scene.frame.frame.depth.size(), CV_8UC1);
  scene.frame.frame.depth.forEach<float>([&](float z, const int* p) {
    no_depth.at<uint8_t>(p[0], p[1]) = std::isnan(z) ? 255 : 0;
  });
  const std::vector<cv::Mat> masks = Masks(scene.frame.frame, {});
  IncrementalOptions unfilled;
  unfilled.detect.fill_speckled_dropout = false;
  const std::vector<cv::Mat> without = Masks(scene.frame.frame, unfilled);
  for (const synth::ObjectTruth& truth : scene.objects) {
    const cv::Mat object = scene.frame.labels == truth.label;
    // Most of its pixels have no depth.
    ASSERT_GT(cv::countNonZero(object & no_depth),
              cv::countNonZero(object) / 2);
    const OnObject found = Score(masks, object);
    EXPECT_EQ(found.masks, 1) << "object " << truth.label;
    EXPECT_GE(found.best_f, 0.75) << "object " << truth.label;
    // Without the fill, no mask finds it (why this test exists).
    EXPECT_LT(Score(without, object).best_f, 0.5) << "object " << truth.label;
  }
}

}  // namespace
}  // namespace fovea
