#include "core/pipeline/detect.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>

#include "core/synth/room.h"
#include "core/synth/synth_scene.h"

namespace fovea {
namespace {

TEST(DetectTest, FirstPointLiesOnAnObjectInSyntheticScenes) {
  int on_object = 0;
  constexpr int kScenes = 8;
  for (int seed = 1; seed <= kScenes; ++seed) {
    const synth::SynthScene scene = synth::GenerateScene(seed);
    absl::StatusOr<DetectResult> result = RunDetect(scene.frame.frame, {});
    ASSERT_TRUE(result.ok()) << "seed " << seed << ": " << result.status();
    ASSERT_FALSE(result->points.empty()) << "seed " << seed;
    const AttentionPoint& p = result->points[0];
    on_object += scene.frame.labels.at<int>(p.v, p.u) >= 20;
    EXPECT_FALSE(std::isnan(p.point.z()));
  }
  EXPECT_GE(on_object, kScenes - 1);
}

// A driver that drops every other column, every other row or every 4th
// column of depth: the table is still found and the first point still
// lies on an object, in every scene where it does with all the depth.
TEST(DetectTest, RegularDepthDropoutsStillFindTheObjects) {
  struct Pattern {
    const char* name;
    int column_period;  // 0: no missing columns
    int row_period;
  };
  for (int seed = 1; seed <= 4; ++seed) {
    const synth::SynthScene scene = synth::GenerateScene(seed);
    absl::StatusOr<DetectResult> whole = RunDetect(scene.frame.frame, {});
    ASSERT_TRUE(whole.ok()) << seed;
    ASSERT_FALSE(whole->points.empty());
    const AttentionPoint& first = whole->points[0];
    if (scene.frame.labels.at<int>(first.v, first.u) < 20) continue;
    for (const Pattern& pattern :
         {Pattern{"every other column", 2, 0}, Pattern{"every other row", 0, 2},
          Pattern{"every 4th column", 4, 0}}) {
      RgbdFrame frame = scene.frame.frame;
      frame.depth = frame.depth.clone();
      for (int v = 0; v < frame.height(); ++v) {
        for (int u = 0; u < frame.width(); ++u) {
          if ((pattern.column_period && u % pattern.column_period == 0) ||
              (pattern.row_period && v % pattern.row_period == 0)) {
            frame.depth.at<float>(v, u) =
                std::numeric_limits<float>::quiet_NaN();
          }
        }
      }
      absl::StatusOr<DetectResult> result = RunDetect(frame, {});
      ASSERT_TRUE(result.ok())
          << "seed " << seed << ", " << pattern.name << ": " << result.status();
      ASSERT_FALSE(result->points.empty()) << seed << ", " << pattern.name;
      const AttentionPoint& p = result->points[0];
      EXPECT_GE(scene.frame.labels.at<int>(p.v, p.u), 20)
          << "seed " << seed << ", " << pattern.name;
    }
  }
}

TEST(DetectTest, DefaultsGiveAStackedBoxItsOwnPoint) {
  // A small box on a large one: one region of the thesis's master map,
  // two once it is split at the fold between them.
  synth::SceneSpec spec;
  spec.camera_pose = synth::LookAt({0.0f, -0.75f, 0.75f}, {0.0f, 0.0f, 0.0f});
  synth::Primitive bottom;
  bottom.half_extents = {0.1f, 0.06f, 0.06f};
  bottom.pose.translation() = Eigen::Vector3f(0.0f, 0.05f, 0.06f);
  synth::Primitive top = bottom;
  top.half_extents = {0.05f, 0.04f, 0.04f};
  top.pose.translation() = Eigen::Vector3f(0.0f, 0.05f, 0.16f);
  spec.objects = {bottom, top};
  const synth::SynthScene scene = synth::RenderScene(spec, {}, 7);
  auto objects_hit_by_first_two = [&](const DetectOptions& options) {
    absl::StatusOr<DetectResult> result = RunDetect(scene.frame.frame, options);
    EXPECT_TRUE(result.ok()) << result.status();
    std::set<int> hit;
    for (size_t i = 0; result.ok() && i < result->points.size() && i < 2; ++i) {
      const int label =
          scene.frame.labels.at<int>(result->points[i].v, result->points[i].u);
      if (label >= 20) hit.insert(label);
    }
    return hit.size();
  };
  EXPECT_EQ(objects_hit_by_first_two(DetectOptions{}), 2u);
  DetectOptions thesis;
  thesis.split_at_surface_edges = false;
  EXPECT_LT(objects_hit_by_first_two(thesis), 2u);
}

TEST(DetectTest, PointsComeMostSalientFirstWithTimings) {
  const synth::SynthScene scene = synth::GenerateScene(3);
  DetectOptions options;
  options.channels = {
      {SaliencyOp::kPh, 1}, {SaliencyOp::kSh, 1}, {SaliencyOp::kRso, 2}};
  options.keep_channel_maps = true;
  absl::StatusOr<DetectResult> result = RunDetect(scene.frame.frame, options);
  ASSERT_TRUE(result.ok()) << result.status();
  for (size_t i = 1; i < result->points.size(); ++i) {
    EXPECT_GE(result->points[i - 1].saliency, result->points[i].saliency);
  }
  ASSERT_EQ(result->channel_maps.size(), 3u);
  EXPECT_EQ(result->channel_maps[0].name, "ph");
  bool has_normals = false, has_plane = false;
  for (const StageTiming& t : result->timings) {
    has_normals |= t.stage == "normals";
    has_plane |= t.stage == "support_plane";
  }
  EXPECT_TRUE(has_normals && has_plane);
}

TEST(DetectTest, EveryOperatorRunsAlone) {
  const synth::SynthScene scene = synth::GenerateScene(5);
  for (SaliencyOp op :
       {SaliencyOp::kPh, SaliencyOp::kSh, SaliencyOp::kRso, SaliencyOp::kSym3d,
        SaliencyOp::kItti, SaliencyOp::kHarel, SaliencyOp::kHou,
        SaliencyOp::kKootstra, SaliencyOp::kTargetColor,
        SaliencyOp::kLocationPrior}) {
    SCOPED_TRACE(SaliencyOpName(op));
    DetectOptions options;
    options.channels = {{op, 1}};
    options.location_prior = {320.0f, 240.0f, 60.0f};
    const Eigen::Vector3f albedo = scene.objects[0].primitive.rgb * 255.0f;
    options.target_color.rgb = {static_cast<uint8_t>(albedo.x()),
                                static_cast<uint8_t>(albedo.y()),
                                static_cast<uint8_t>(albedo.z())};
    absl::StatusOr<DetectResult> result = RunDetect(scene.frame.frame, options);
    ASSERT_TRUE(result.ok()) << result.status();
    EXPECT_FALSE(result->points.empty());
  }
}

TEST(DetectTest, LocationPriorAloneAttendsToItsCentre) {
  const synth::SynthScene scene = synth::GenerateScene(5);
  DetectOptions options;
  options.channels = {{SaliencyOp::kLocationPrior, 1}};
  // A Gaussian over the whole image has a mean far below 10 % of its peak,
  // which TJ drops (theta_sal); MSR takes its peak.
  options.extraction = ExtractionKind::kMsr;
  options.location_prior = {100.0f, 300.0f, 30.0f};
  absl::StatusOr<DetectResult> result = RunDetect(scene.frame.frame, options);
  ASSERT_TRUE(result.ok());
  ASSERT_FALSE(result->points.empty());
  EXPECT_NEAR(result->points[0].u, 100, 3);
  EXPECT_NEAR(result->points[0].v, 300, 3);
}

TEST(DetectTest, EveryPyramidNormalisationAndExtractionRuns) {
  const synth::SynthScene scene = synth::GenerateScene(4);
  for (PyramidKind pyramid :
       {PyramidKind::kNone, PyramidKind::kSimple, PyramidKind::kItti}) {
    for (NormalizationKind norm :
         {NormalizationKind::kLin, NormalizationKind::kNms,
          NormalizationKind::kNlm}) {
      for (ExtractionKind extract :
           {ExtractionKind::kMsr, ExtractionKind::kWta, ExtractionKind::kTj}) {
        DetectOptions options;
        options.channels = {{SaliencyOp::kSym3d, 1}, {SaliencyOp::kRso, 1}};
        options.pyramid = pyramid;
        options.normalization = norm;
        options.extraction = extract;
        SCOPED_TRACE(::testing::Message()
                     << "pyramid " << static_cast<int>(pyramid) << " norm "
                     << static_cast<int>(norm) << " extract "
                     << ExtractionName(extract));
        absl::StatusOr<DetectResult> result =
            RunDetect(scene.frame.frame, options);
        ASSERT_TRUE(result.ok()) << result.status();
        EXPECT_FALSE(result->points.empty());
        EXPECT_EQ(result->master.size(), scene.frame.frame.depth.size());
      }
    }
  }
}

TEST(DetectTest, BadOptionsNameTheField) {
  DetectOptions options;
  options.max_points = 0;
  EXPECT_NE(Validate(options).message().find("options.max_points"),
            std::string::npos);
  options = {};
  options.min_region_pixels = -1;
  EXPECT_NE(Validate(options).message().find("options.min_region_pixels"),
            std::string::npos);
  options = {};
  options.channels = {{SaliencyOp::kRso, -1.0f}};
  EXPECT_EQ(Validate(options).code(), absl::StatusCode::kInvalidArgument);
}

TEST(DetectTest, InterruptStopsThePipelineWithItsStatus) {
  const synth::SynthScene scene = synth::GenerateScene(1);
  int calls = 0;
  absl::StatusOr<DetectResult> result =
      RunDetect(scene.frame.frame, {}, [&calls]() {
        ++calls;
        return absl::DeadlineExceededError("deadline");
      });
  EXPECT_EQ(result.status().code(), absl::StatusCode::kDeadlineExceeded);
  EXPECT_EQ(calls, 1);
}

TEST(DetectTest, ParsesSaliencyNamesAndCombinations) {
  absl::StatusOr<std::vector<SaliencyOp>> ops = ParseSaliencyOps("ph+sh+rso");
  ASSERT_TRUE(ops.ok());
  EXPECT_EQ(ops->size(), 3u);
  EXPECT_EQ((*ops)[2], SaliencyOp::kRso);
  const absl::Status bad = ParseSaliencyOps("ph+bogus").status();
  EXPECT_NE(bad.message().find("bogus"), std::string::npos);
  EXPECT_EQ(*ParseExtraction("msr"), ExtractionKind::kMsr);
  EXPECT_FALSE(ParseExtraction("xyz").ok());
}

TEST(DetectTest, PyramidNamesRoundTripAndOtherNamesAreNamed) {
  for (PyramidKind kind :
       {PyramidKind::kNone, PyramidKind::kSimple, PyramidKind::kItti}) {
    EXPECT_EQ(*ParsePyramid(PyramidName(kind)), kind);
  }
  EXPECT_EQ(*ParseLevelCombination("max"), LevelCombination::kMax);
  EXPECT_EQ(*ParseNormalization("nlm"), NormalizationKind::kNlm);
  EXPECT_EQ(*ParseFusion("sum"), FusionKind::kSum);
  EXPECT_NE(ParsePyramid("gauss").status().message().find("gauss"),
            std::string::npos);
  EXPECT_FALSE(ParseLevelCombination("-").ok());
  EXPECT_FALSE(ParseNormalization("l2").ok());
  EXPECT_FALSE(ParseFusion("mean").ok());
}

}  // namespace
}  // namespace fovea

namespace fovea {
namespace {

TEST(DetectTest, DuplicateChannelsAreRefusedNamingTheOperator) {
  DetectOptions options;
  options.channels = {
      {SaliencyOp::kPh, 1}, {SaliencyOp::kRso, 1}, {SaliencyOp::kPh, 2}};
  const absl::Status s = Validate(options);
  EXPECT_EQ(s.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(s.message().find("'ph'"), std::string::npos);
}

TEST(DetectTest, StageNamesCoverEveryStageARunReports) {
  const std::vector<std::string> names = DetectStageNames();
  const synth::SynthScene scene = synth::GenerateScene(2);
  DetectOptions options;
  options.channels = {
      {SaliencyOp::kPh, 1}, {SaliencyOp::kSh, 1}, {SaliencyOp::kRso, 1}};
  absl::StatusOr<DetectResult> result = RunDetect(scene.frame.frame, options);
  ASSERT_TRUE(result.ok());
  for (const StageTiming& t : result->timings) {
    EXPECT_NE(std::find(names.begin(), names.end(), t.stage), names.end())
        << t.stage;
  }
  EXPECT_NE(std::find(names.begin(), names.end(), "saliency.sym3d"),
            names.end());
  EXPECT_NE(std::find(names.begin(), names.end(), "extract.tj"), names.end());
  EXPECT_NE(std::find(names.begin(), names.end(), "saliency.itti"),
            names.end());
}

}  // namespace
}  // namespace fovea

namespace fovea {
namespace {

TEST(RunDetectWideFrameTest,
     ReducedProcessingReturnsInputPixelsAndTheirPoints) {
  synth::RoomOptions room;
  room.sensor = synth::RoomSensor::kActiveStereo;
  room.width = 1280;
  room.height = 720;
  const synth::SynthScene scene = synth::GenerateRoom(5, room);
  absl::StatusOr<DetectResult> result =
      RunDetect(scene.frame.frame, DetectOptions{});
  ASSERT_TRUE(result.ok()) << result.status();
  EXPECT_EQ(result->master.size(), cv::Size(1280, 720));
  EXPECT_EQ(result->plane.inliers.size(), cv::Size(1280, 720));
  ASSERT_FALSE(result->points.empty());
  EXPECT_EQ(result->timings.front().stage, "reduce");
  const Intrinsics& k = scene.frame.frame.intrinsics;
  for (const AttentionPoint& p : result->points) {
    ASSERT_LT(p.u, 1280);
    ASSERT_LT(p.v, 720);
    // The 3D point is where the input pixel looks, within a reduced pixel
    // and the depth noise.
    const float z = scene.frame.frame.depth.at<float>(p.v, p.u);
    if (std::isnan(z) || std::isnan(p.point.z())) continue;
    const Eigen::Vector3f seen((p.u - k.cx) * z / k.fx, (p.v - k.cy) * z / k.fy,
                               z);
    EXPECT_LT((seen - p.point).norm(), 0.03f) << p.u << "," << p.v;
  }
  // The same frame at its own resolution finds the same support.
  DetectOptions full;
  full.scene.processing_width = 1280;
  absl::StatusOr<DetectResult> native = RunDetect(scene.frame.frame, full);
  ASSERT_TRUE(native.ok()) << native.status();
  EXPECT_GT(native->plane.normal.dot(result->plane.normal), std::cos(0.02f));
  EXPECT_NEAR(native->plane.d, result->plane.d, 0.01f);
}

}  // namespace
}  // namespace fovea
