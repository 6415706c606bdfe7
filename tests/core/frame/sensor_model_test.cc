#include "core/frame/sensor_model.h"

#include <gtest/gtest.h>

namespace fovea {
namespace {

TEST(SensorModelTest, NamesRoundTripAndUnknownNamesListTheKnownOnes) {
  for (const SensorKind kind :
       {SensorKind::kGeneric, SensorKind::kKinectV1, SensorKind::kActiveStereo,
        SensorKind::kTimeOfFlight}) {
    absl::StatusOr<SensorKind> parsed = ParseSensorKind(SensorKindName(kind));
    ASSERT_TRUE(parsed.ok());
    EXPECT_EQ(*parsed, kind);
  }
  const absl::StatusOr<SensorKind> bad = ParseSensorKind("kinect");
  EXPECT_EQ(bad.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(bad.status().message().find("active_stereo"), std::string::npos);
}

TEST(SensorModelTest, KinectNoiseIsKhoshelhamsQuadratic) {
  const SensorModel k =
      SensorModelFor(SensorKind::kKinectV1, kKinectV1Intrinsics);
  EXPECT_NEAR(k.DepthSigma(1.0f), 1.43e-3f, 1e-6f);
  EXPECT_NEAR(k.DepthSigma(2.0f), 4.0f * 1.43e-3f, 1e-6f);
}

TEST(SensorModelTest, ActiveStereoIsNoisierThanTheKinectAtEveryRange) {
  const SensorModel k =
      SensorModelFor(SensorKind::kKinectV1, kKinectV1Intrinsics);
  const SensorModel s =
      SensorModelFor(SensorKind::kActiveStereo, {613.0, 613.0, 322.5, 248.2});
  for (const float z : {0.3f, 0.7f, 1.0f, 2.0f, 3.0f}) {
    EXPECT_GT(s.DepthSigma(z), k.DepthSigma(z)) << z;
  }
  // A millimetre floor: what the RealSense frames' table tops show at 0.5 m.
  EXPECT_GT(s.DepthSigma(0.5f), 0.001f);
}

TEST(SensorModelTest, GenericPicksTheModelFromTheFocalLength) {
  // OSD's Kinect (525 px at 640), an Xtion (570 px): structured light.
  for (const Intrinsics& k :
       {kKinectV1Intrinsics, Intrinsics{570.3, 570.3, 319.5, 239.5},
        Intrinsics{262.5, 262.5, 159.5, 119.5}}) {
    const SensorModel g = SensorModelFor(SensorKind::kGeneric, k);
    EXPECT_EQ(g.kind, SensorKind::kGeneric);
    EXPECT_EQ(g.sigma_per_z2,
              SensorModelFor(SensorKind::kKinectV1, k).sigma_per_z2)
        << k.fx;
  }
  // The same cameras rolled a quarter turn (a wrist camera turned
  // sideways: 480 columns, 640 rows, the principal point swapped).
  for (const Intrinsics& k : {Intrinsics{525.0, 525.0, 239.5, 319.5},
                              Intrinsics{570.3, 570.3, 239.5, 319.5}}) {
    EXPECT_EQ(SensorModelFor(SensorKind::kGeneric, k).sigma_per_z2,
              SensorModelFor(SensorKind::kKinectV1, k).sigma_per_z2)
        << k.fx;
  }
  // A RealSense colour camera at 640x480 and at 1280x720, a depth stream
  // (385 px at 640): the active-stereo model, 3 m range.
  for (const Intrinsics& k : {Intrinsics{612.9, 613.2, 322.5, 248.2},
                              Intrinsics{920.0, 920.0, 640.0, 360.0},
                              Intrinsics{385.0, 385.0, 320.0, 240.0}}) {
    const SensorModel g = SensorModelFor(SensorKind::kGeneric, k);
    EXPECT_EQ(g.sigma_per_z2,
              SensorModelFor(SensorKind::kActiveStereo, k).sigma_per_z2)
        << k.fx;
    EXPECT_FLOAT_EQ(g.max_range_m, 3.0f);
  }
}

TEST(SensorModelTest, TimeOfFlightIsQuieterThanStereoAndTheFarKinect) {
  const Intrinsics azure{504.2, 504.3, 321.0, 331.5};  // 640x576
  const SensorModel t = SensorModelFor(SensorKind::kTimeOfFlight, azure);
  const SensorModel s = SensorModelFor(SensorKind::kActiveStereo, azure);
  const SensorModel k = SensorModelFor(SensorKind::kKinectV1, azure);
  for (const float z : {0.3f, 0.7f, 1.0f, 2.0f, 3.0f}) {
    EXPECT_LT(t.DepthSigma(z), s.DepthSigma(z)) << z;
  }
  // Per-pixel noise a millimetre and a half at 1 m, growing slowly: the
  // Kinect's quadratic overtakes it beyond a metre.
  EXPECT_NEAR(t.DepthSigma(1.0f), 0.0015f, 1e-6f);
  for (const float z : {1.5f, 2.0f, 3.0f}) {
    EXPECT_LT(t.DepthSigma(z), k.DepthSigma(z)) << z;
  }
}

TEST(SensorModelTest, GenericTakesANearlySquareFrameForTimeOfFlight) {
  // Azure Kinect NFOV 640x576 (its fx640 of 504 would pass for a
  // PrimeSense), WFOV binned 512x512, Kinect v2 512x424 (principal point a
  // few pixels off centre), and the Azure frame rolled a quarter turn.
  for (const Intrinsics& k : {Intrinsics{504.2, 504.3, 321.0, 331.5},
                              Intrinsics{252.0, 252.0, 255.5, 255.5},
                              Intrinsics{365.5, 365.5, 256.5, 210.5},
                              Intrinsics{504.3, 504.2, 331.5, 321.0}}) {
    EXPECT_EQ(NoiseKind(SensorKind::kGeneric, k), SensorKind::kTimeOfFlight)
        << k.fx << " " << k.cx << " " << k.cy;
    EXPECT_EQ(SensorModelFor(SensorKind::kGeneric, k).sigma_per_z2,
              SensorModelFor(SensorKind::kTimeOfFlight, k).sigma_per_z2);
  }
  // 4:3 with the principal point 8 px off centre each way is still 4:3.
  EXPECT_EQ(NoiseKind(SensorKind::kGeneric, {525.0, 525.0, 311.5, 247.5}),
            SensorKind::kKinectV1);
  EXPECT_EQ(NoiseKind(SensorKind::kGeneric, {612.9, 613.2, 311.5, 247.5}),
            SensorKind::kActiveStereo);
}

TEST(SensorModelTest, NoiseKindIsTheModelGenericChoseForTheWholeFrame) {
  EXPECT_EQ(NoiseKind(SensorKind::kGeneric, kKinectV1Intrinsics),
            SensorKind::kKinectV1);
  EXPECT_EQ(
      NoiseKind(SensorKind::kGeneric, Intrinsics{612.9, 613.2, 322.5, 248.2}),
      SensorKind::kActiveStereo);
  // A named kind is itself, whatever the intrinsics.
  EXPECT_EQ(NoiseKind(SensorKind::kActiveStereo, kKinectV1Intrinsics),
            SensorKind::kActiveStereo);
  // A 200 x 150 cut-out of the Kinect's frame (its principal point moved
  // by the corner, 220, 165) would pass for another camera: the reason a
  // part of a frame takes the whole frame's kind.
  const Intrinsics cut{525.0, 525.0, 99.5, 74.5};
  EXPECT_EQ(NoiseKind(SensorKind::kGeneric, cut), SensorKind::kActiveStereo);
}

}  // namespace
}  // namespace fovea
