#include "core/pipeline/sensor_adaptation.h"

#include <gtest/gtest.h>

#include <cmath>

namespace fovea {
namespace {

TEST(SensorAdaptationTest, KinectLeavesEveryDefaultAsItIs) {
  const SensorModel kinect =
      SensorModelFor(SensorKind::kKinectV1, kKinectV1Intrinsics);
  SupportPlaneOptions support;
  TableSceneOptions table;
  SurfaceModelOptions surfaces;
  AdaptToSensor(kinect, support);
  AdaptToSensor(kinect, table);
  AdaptToSensor(kinect, surfaces);
  EXPECT_EQ(support.sigma_per_z2, SupportPlaneOptions().sigma_per_z2);
  EXPECT_EQ(support.sigma0_m, SupportPlaneOptions().sigma0_m);
  EXPECT_EQ(table.sigma_per_z2, TableSceneOptions().sigma_per_z2);
  EXPECT_EQ(table.sigma0_m, TableSceneOptions().sigma0_m);
  EXPECT_EQ(surfaces.surface_sigma, SurfaceModelOptions().surface_sigma);
  EXPECT_EQ(surfaces.sigma_per_z2, SurfaceModelOptions().sigma_per_z2);
}

TEST(SensorAdaptationTest, ActiveStereoWidensTheBandsByItsNoise) {
  const SensorModel stereo =
      SensorModelFor(SensorKind::kActiveStereo, {613.0, 613.0, 322.5, 248.2});
  SupportPlaneOptions support;
  TableSceneOptions table;
  SurfaceModelOptions surfaces;
  AdaptToSensor(stereo, support);
  AdaptToSensor(stereo, table);
  AdaptToSensor(stereo, surfaces);
  EXPECT_EQ(support.sigma_per_z2, stereo.sigma_per_z2);
  EXPECT_EQ(support.sigma0_m, stereo.sigma0_m);
  EXPECT_EQ(table.sigma_per_z2, stereo.sigma_per_z2);
  EXPECT_EQ(table.sigma0_m, stereo.sigma0_m);
  // The millimetre floor joins surface_sigma in quadrature: 1 mm and 1 mm
  // make 1.41 mm. The z^2 term stays the Kinect's (docs/segmentation.md).
  EXPECT_NEAR(surfaces.surface_sigma,
              std::hypot(SurfaceModelOptions().surface_sigma, 0.001f), 1e-7f);
  EXPECT_EQ(surfaces.sigma_per_z2, SurfaceModelOptions().sigma_per_z2);
}

}  // namespace
}  // namespace fovea
