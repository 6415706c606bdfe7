#include "server/convert.h"

#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "core/frame/sensor_model.h"
#include "core/synth/synth_scene.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "server/capabilities.h"

namespace fovea::server {
namespace {

using ::testing::HasSubstr;

TEST(ToDetectOptionsTest, EmptyOptionsAreCoreDefaults) {
  absl::StatusOr<DetectOptions> options = ToDetectOptions(v1::DetectOptions());
  ASSERT_TRUE(options.ok()) << options.status();
  const DetectOptions defaults;
  ASSERT_EQ(options->channels.size(), defaults.channels.size());
  EXPECT_EQ(options->channels[0].op, defaults.channels[0].op);
  EXPECT_EQ(options->max_points, kMaxAttentionPoints);  // one per region
  EXPECT_EQ(options->pyramid, defaults.pyramid);
  EXPECT_EQ(options->extraction, defaults.extraction);
  EXPECT_EQ(options->split_at_surface_edges, defaults.split_at_surface_edges);
  EXPECT_FALSE(options->keep_channel_maps);
}

TEST(ToDetectOptionsTest, SurfaceEdgeSplitIsDefaultUnlessSet) {
  for (const bool split : {false, true}) {
    v1::DetectOptions in;
    in.set_split_at_surface_edges(split);
    absl::StatusOr<DetectOptions> options = ToDetectOptions(in);
    ASSERT_TRUE(options.ok()) << options.status();
    EXPECT_EQ(options->split_at_surface_edges, split);
  }
}

TEST(ToDetectOptionsTest, ChannelsWithZeroWeightWeighOne) {
  v1::DetectOptions in;
  in.add_saliency()->set_op(v1::SALIENCY_OPERATOR_PH);
  v1::WeightedOperator* sh = in.add_saliency();
  sh->set_op(v1::SALIENCY_OPERATOR_SH);
  sh->set_weight(0.25);
  in.set_max_points(3);
  in.set_return_channel_maps(true);
  absl::StatusOr<DetectOptions> options = ToDetectOptions(in);
  ASSERT_TRUE(options.ok()) << options.status();
  ASSERT_EQ(options->channels.size(), 2u);
  EXPECT_EQ(options->channels[0].op, SaliencyOp::kPh);
  EXPECT_FLOAT_EQ(options->channels[0].weight, 1.0f);
  EXPECT_EQ(options->channels[1].op, SaliencyOp::kSh);
  EXPECT_FLOAT_EQ(options->channels[1].weight, 0.25f);
  EXPECT_EQ(options->max_points, 3);
  EXPECT_TRUE(options->keep_channel_maps);
}

TEST(ToDetectOptionsTest, NegativeWeightIsInvalidAndNamed) {
  v1::DetectOptions in;
  in.add_saliency()->set_op(v1::SALIENCY_OPERATOR_RSO);
  v1::WeightedOperator* ph = in.add_saliency();
  ph->set_op(v1::SALIENCY_OPERATOR_PH);
  ph->set_weight(-1.0);
  absl::Status status = ToDetectOptions(in).status();
  EXPECT_EQ(status.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(status.message(), HasSubstr("options.saliency[1].weight"));
}

TEST(ToDetectOptionsTest, ChannelWithoutOperatorIsInvalid) {
  v1::DetectOptions in;
  in.add_saliency()->set_weight(1.0);
  absl::Status status = ToDetectOptions(in).status();
  EXPECT_EQ(status.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(status.message(), HasSubstr("options.saliency[0].op"));
}

TEST(ToDetectOptionsTest, MaxPointsAboveCoresLimitIsInvalid) {
  v1::DetectOptions in;
  in.set_max_points(kMaxAttentionPoints);
  EXPECT_TRUE(ToDetectOptions(in).ok());
  in.set_max_points(kMaxAttentionPoints + 1);
  absl::Status status = ToDetectOptions(in).status();
  EXPECT_EQ(status.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(status.message(), HasSubstr("options.max_points"));
}

TEST(ToDetectOptionsTest, ValueOutsideTheEnumIsInvalidAndNamed) {
  v1::DetectOptions in;
  in.set_pyramid(static_cast<v1::Pyramid>(99));
  absl::Status status = ToDetectOptions(in).status();
  EXPECT_EQ(status.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(status.message(), HasSubstr("options.pyramid"));
}

TEST(ToDetectOptionsTest, TopDownCuesAreCopiedAndRequired) {
  v1::DetectOptions in;
  in.add_saliency()->set_op(v1::SALIENCY_OPERATOR_TARGET_COLOR);
  absl::Status status = ToDetectOptions(in).status();
  EXPECT_EQ(status.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(status.message(), HasSubstr("options.target_color_rgb"));
  in.add_target_color_rgb(250);
  in.add_target_color_rgb(200);
  in.add_target_color_rgb(10);
  absl::StatusOr<DetectOptions> out = ToDetectOptions(in);
  ASSERT_TRUE(out.ok()) << out.status();
  EXPECT_EQ(out->target_color.rgb[1], 200);

  v1::DetectOptions prior;
  prior.add_saliency()->set_op(v1::SALIENCY_OPERATOR_LOCATION_PRIOR);
  status = ToDetectOptions(prior).status();
  EXPECT_THAT(status.message(), HasSubstr("options.location_prior"));
  prior.mutable_location_prior()->set_u(100);
  prior.mutable_location_prior()->set_v(50);
  prior.set_location_prior_sigma_px(20);
  out = ToDetectOptions(prior);
  ASSERT_TRUE(out.ok()) << out.status();
  EXPECT_EQ(out->location_prior.u, 100.0f);
  EXPECT_EQ(out->location_prior.sigma_px, 20.0f);
}

TEST(ToDetectOptionsTest, EveryStrategyOfTheThesisIsAccepted) {
  v1::DetectOptions in;
  in.add_saliency()->set_op(v1::SALIENCY_OPERATOR_SYM3D);
  in.set_pyramid(v1::PYRAMID_ITTI);
  in.set_normalization(v1::NORMALIZATION_NLM);
  in.set_extraction(v1::EXTRACTION_TJ);
  absl::StatusOr<DetectOptions> out = ToDetectOptions(in);
  ASSERT_TRUE(out.ok()) << out.status();
  EXPECT_EQ(out->pyramid, PyramidKind::kItti);
  EXPECT_EQ(out->extraction, ExtractionKind::kTj);
}

TEST(ToDetectOptionsTest, BadTopDownCuesAreInvalid) {
  v1::DetectOptions two_values;
  two_values.add_target_color_rgb(1);
  two_values.add_target_color_rgb(2);
  EXPECT_THAT(ToDetectOptions(two_values).status().message(),
              HasSubstr("options.target_color_rgb"));
  v1::DetectOptions too_bright;
  for (uint32_t c : {10u, 300u, 10u}) too_bright.add_target_color_rgb(c);
  EXPECT_THAT(ToDetectOptions(too_bright).status().message(),
              HasSubstr("options.target_color_rgb[1]"));
  v1::DetectOptions sigma;
  sigma.set_location_prior_sigma_px(-2);
  EXPECT_THAT(ToDetectOptions(sigma).status().message(),
              HasSubstr("options.location_prior_sigma_px"));
}

TEST(ToDetectOptionsTest, DefaultsSurviveTheWire) {
  const DetectOptions defaults;
  absl::StatusOr<DetectOptions> back =
      ToDetectOptions(ToProtoDetectOptions(defaults));
  ASSERT_TRUE(back.ok()) << back.status();
  ASSERT_EQ(back->channels.size(), defaults.channels.size());
  for (size_t i = 0; i < defaults.channels.size(); ++i) {
    EXPECT_EQ(back->channels[i].op, defaults.channels[i].op);
    EXPECT_FLOAT_EQ(back->channels[i].weight, defaults.channels[i].weight);
  }
  EXPECT_EQ(back->pyramid, defaults.pyramid);
  EXPECT_EQ(back->level_combination, defaults.level_combination);
  EXPECT_EQ(back->normalization, defaults.normalization);
  EXPECT_EQ(back->fusion, defaults.fusion);
  EXPECT_EQ(back->extraction, defaults.extraction);
  EXPECT_EQ(back->max_points, defaults.max_points);
  EXPECT_EQ(back->split_at_surface_edges, defaults.split_at_surface_edges);
}

TEST(ToDetectOptionsTest, SceneOptionsReachCore) {
  v1::DetectOptions in;
  v1::SceneOptions* scene = in.mutable_scene();
  scene->set_sensor(v1::SENSOR_MODEL_ACTIVE_STEREO);
  scene->set_processing_width(800);
  scene->mutable_gravity()->set_y(1.0);
  scene->mutable_support_plane()->mutable_normal()->set_y(-1.0);
  scene->mutable_support_plane()->set_d(0.7);
  scene->mutable_workspace()->set_max_depth_m(2.5);
  scene->mutable_workspace()->mutable_box()->mutable_min()->set_x(-1.0);
  scene->mutable_workspace()->mutable_box()->mutable_min()->set_y(-1.0);
  scene->mutable_workspace()->mutable_box()->mutable_max()->set_x(1.0);
  scene->mutable_workspace()->mutable_box()->mutable_max()->set_y(1.0);
  scene->mutable_workspace()->mutable_box()->mutable_max()->set_z(2.0);
  absl::StatusOr<DetectOptions> out = ToDetectOptions(in);
  ASSERT_TRUE(out.ok()) << out.status();
  EXPECT_EQ(out->scene.sensor, SensorKind::kActiveStereo);
  EXPECT_EQ(out->scene.processing_width, 800);
  ASSERT_TRUE(out->scene.support.gravity.has_value());
  EXPECT_FLOAT_EQ(out->scene.support.gravity->y(), 1.0f);
  ASSERT_TRUE(out->scene.support.plane.has_value());
  EXPECT_FLOAT_EQ((*out->scene.support.plane)[3], 0.7f);
  EXPECT_FLOAT_EQ(out->scene.workspace.max_depth_m, 2.5f);
  ASSERT_TRUE(out->scene.workspace.box.has_value());
  EXPECT_FLOAT_EQ(out->scene.workspace.box->max.z(), 2.0f);
  // Unset, the scene is the default one.
  absl::StatusOr<DetectOptions> plain = ToDetectOptions(v1::DetectOptions());
  ASSERT_TRUE(plain.ok());
  EXPECT_EQ(plain->scene.sensor, SensorKind::kGeneric);
  EXPECT_EQ(plain->scene.processing_width, 640);
  EXPECT_FALSE(plain->scene.support.gravity.has_value());
  EXPECT_FALSE(plain->scene.workspace.box.has_value());
}

// Every sensor core knows has a wire value that comes back as itself.
TEST(ToDetectOptionsTest, EverySensorSurvivesTheWire) {
  for (const NamedValue<SensorKind>& sensor : SensorKinds()) {
    DetectOptions options;
    options.scene.sensor = sensor.value;
    const absl::StatusOr<DetectOptions> back =
        ToDetectOptions(ToProtoDetectOptions(options));
    ASSERT_TRUE(back.ok()) << sensor.name << ": " << back.status();
    EXPECT_EQ(back->scene.sensor, sensor.value) << sensor.name;
  }
  EXPECT_EQ(ToProtoEnum(SensorKind::kTimeOfFlight),
            v1::SENSOR_MODEL_TIME_OF_FLIGHT);
}

TEST(ToDetectOptionsTest, BadSceneHintsAreInvalidAndNamed) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  struct Case {
    std::function<void(v1::SceneOptions&)> set;
    std::string field;
  };
  const std::vector<Case> cases = {
      {[&](v1::SceneOptions& s) { s.mutable_gravity()->set_x(nan); },
       "options.scene.gravity: must be finite"},
      {[](v1::SceneOptions& s) { s.mutable_gravity(); },  // zero vector
       "options.scene.gravity: must be a unit vector"},
      {[](v1::SceneOptions& s) { s.mutable_gravity()->set_z(3.0); },
       "options.scene.gravity: must be a unit vector, got length 3"},
      {[](v1::SceneOptions& s) {
         s.mutable_support_plane()->mutable_normal()->set_y(0.5);
       },
       "options.scene.support_plane.normal"},
      {[&](v1::SceneOptions& s) {
         s.mutable_support_plane()->mutable_normal()->set_y(1.0);
         s.mutable_support_plane()->set_d(nan);
       },
       "options.scene.support_plane.d"},
      {[](v1::SceneOptions& s) { s.mutable_workspace()->mutable_box(); },
       "options.scene.workspace.box is empty"},
      {[](v1::SceneOptions& s) {
         s.mutable_workspace()->set_min_depth_m(2.0);
         s.mutable_workspace()->set_max_depth_m(1.0);
       },
       "options.scene.workspace.max_depth_m must exceed"},
      {[](v1::SceneOptions& s) {
         s.mutable_workspace()->set_max_depth_m(-1.0);
       },
       "options.scene.workspace.max_depth_m"},
      {[](v1::SceneOptions& s) { s.set_processing_width(50); },
       "options.scene.processing_width"},
      {[](v1::SceneOptions& s) {
         s.set_sensor(static_cast<v1::SensorModel>(77));
       },
       "options.scene.sensor: unknown value 77"},
  };
  for (const Case& c : cases) {
    v1::DetectOptions in;
    c.set(*in.mutable_scene());
    const absl::Status status = ToDetectOptions(in).status();
    EXPECT_EQ(status.code(), absl::StatusCode::kInvalidArgument) << c.field;
    EXPECT_THAT(status.message(), HasSubstr(c.field));
  }
  // Segment requests name the nested field.
  v1::SegmentRequest request;
  request.mutable_detect_options()->mutable_scene()->mutable_gravity();
  EXPECT_THAT(ToSegmentOptions(request).status().message(),
              HasSubstr("detect_options.options.scene.gravity"));
}

TEST(ToSegmentOptionsTest, CoverSceneIsLeftToCoreUnlessSet) {
  v1::SegmentRequest request;
  absl::StatusOr<SegmentOptions> unset = ToSegmentOptions(request);
  ASSERT_TRUE(unset.ok()) << unset.status();
  EXPECT_FALSE(unset->cover_scene.has_value());
  request.set_cover_scene(false);
  absl::StatusOr<SegmentOptions> off = ToSegmentOptions(request);
  ASSERT_TRUE(off.ok()) << off.status();
  EXPECT_EQ(off->cover_scene, std::optional<bool>(false));
}

TEST(ToProtoSupportPlaneTest, CarriesTheChoiceAndItsScore) {
  SupportPlane plane;
  plane.normal = {0.0f, -0.8f, -0.6f};
  plane.d = 0.7f;
  plane.inlier_count = 1234;
  plane.candidate_count = 4;
  plane.score.total = 5.5;
  plane.score.objects = 3;
  plane.score.area_m2 = 0.5f;
  plane.score.distance_m = 0.9f;
  plane.score.tilt_deg = 1.5f;
  const v1::SupportPlane out = ToProtoSupportPlane(plane);
  EXPECT_FLOAT_EQ(out.normal().y(), -0.8f);
  EXPECT_EQ(out.inlier_count(), 1234u);
  EXPECT_EQ(out.candidate_count(), 4u);
  EXPECT_DOUBLE_EQ(out.score().total(), 5.5);
  EXPECT_EQ(out.score().objects(), 3u);
  EXPECT_FALSE(out.score().under_another());
  EXPECT_FALSE(out.given());
  // The first message of a stream carries it.
  const v1::SegmentResponse first = ToPointsMessage({}, "r", &plane);
  EXPECT_EQ(first.support_plane().candidate_count(), 4u);
  EXPECT_FALSE(ToPointsMessage({}, "r").has_support_plane());
}

TEST(ToRawFrameTest, ViewsPointIntoTheRequest) {
  v1::Frame frame;
  frame.mutable_color()->set_width(2);
  frame.mutable_color()->set_height(1);
  frame.mutable_color()->set_encoding("bgr8");
  frame.mutable_color()->set_step(6);
  frame.mutable_color()->set_data("abcdef");
  frame.mutable_depth()->set_compressed("png bytes");
  frame.mutable_intrinsics()->set_fx(500);
  frame.mutable_intrinsics()->set_cy(7);
  frame.set_depth_scale(0.0001);
  const RawFrame raw = ToRawFrame(frame);
  EXPECT_EQ(raw.color.width, 2u);
  EXPECT_EQ(raw.color.height, 1u);
  EXPECT_EQ(raw.color.encoding, "bgr8");
  EXPECT_EQ(raw.color.step, 6u);
  EXPECT_EQ(raw.color.data.data(), frame.color().data().data());
  EXPECT_EQ(raw.color.data.size(), 6u);
  EXPECT_EQ(raw.depth.compressed, "png bytes");
  EXPECT_TRUE(raw.depth.data.empty());
  EXPECT_EQ(raw.intrinsics.fx, 500);
  EXPECT_EQ(raw.intrinsics.cy, 7);
  EXPECT_EQ(raw.depth_scale, 0.0001);
}

// ToProtoFrame writes what DecodeFrame reads back: colour exactly, depth
// exactly (32FC1) or to the millimetre (16UC1), no-data pixels as NaN.
TEST(ToProtoFrameTest, RoundTripsThroughDecodeFrame) {
  const synth::SynthScene scene = synth::GenerateScene(7);
  const RgbdFrame& original = scene.frame.frame;
  for (DepthEncoding encoding :
       {DepthEncoding::k32FC1, DepthEncoding::k16UC1}) {
    const v1::Frame wire = ToProtoFrame(original, encoding);
    absl::StatusOr<RgbdFrame> decoded =
        DecodeFrame(ToRawFrame(wire), FrameLimits());
    ASSERT_TRUE(decoded.ok()) << decoded.status();
    EXPECT_EQ(cv::norm(decoded->color, original.color, cv::NORM_INF), 0);
    // Half a millimetre of rounding, plus float error.
    const double tolerance = encoding == DepthEncoding::k32FC1 ? 0.0 : 0.000501;
    int compared = 0;
    for (int v = 0; v < original.depth.rows; ++v) {
      for (int u = 0; u < original.depth.cols; ++u) {
        const float a = original.depth.at<float>(v, u);
        const float b = decoded->depth.at<float>(v, u);
        if (std::isnan(a)) {
          EXPECT_TRUE(std::isnan(b)) << u << "," << v;
          continue;
        }
        ASSERT_NEAR(a, b, tolerance) << u << "," << v;
        ++compared;
      }
    }
    EXPECT_GT(compared, 0);
    EXPECT_EQ(decoded->intrinsics.fx, original.intrinsics.fx);
    EXPECT_EQ(decoded->intrinsics.cx, original.intrinsics.cx);
  }
}

DetectResult SmallResult() {
  DetectResult result;
  AttentionPoint first;
  first.u = 3;
  first.v = 1;
  first.saliency = 1.0f;
  first.point = {0.1f, -0.2f, 0.9f};
  AttentionPoint second;  // no depth: NaN point
  second.u = 0;
  second.v = 0;
  second.saliency = 0.5f;
  result.points = {first, second};
  result.master = cv::Mat(2, 4, CV_32FC1, cv::Scalar(0.0f));
  result.master.at<float>(1, 3) = 1.0f;
  result.master.at<float>(0, 1) = 0.5f;
  result.master.at<float>(0, 2) = std::numeric_limits<float>::quiet_NaN();
  result.master.at<float>(1, 0) = 1.5f;  // clamped
  result.channel_maps = {{"rso", result.master.clone()}};
  result.plane.normal = {0.0f, -1.0f, 0.0f};
  result.plane.d = 0.7f;
  result.plane.inlier_count = 1234;
  result.timings = {{"cloud", 0.001}, {"saliency.rso", 0.002}};
  return result;
}

TEST(ToDetectResponseTest, EchoesIdsAndRanksPoints) {
  v1::DetectRequest request;
  request.set_request_id("r-17");
  request.mutable_frame()->set_frame_id("head_camera");
  request.mutable_frame()->set_stamp_ns(123456789);
  absl::StatusOr<v1::DetectResponse> response =
      ToDetectResponse(SmallResult(), request);
  ASSERT_TRUE(response.ok()) << response.status();
  EXPECT_EQ(response->request_id(), "r-17");
  EXPECT_EQ(response->frame_id(), "head_camera");
  EXPECT_EQ(response->stamp_ns(), 123456789);
  ASSERT_EQ(response->points_size(), 2);
  EXPECT_EQ(response->points(0).u(), 3u);
  EXPECT_EQ(response->points(0).v(), 1u);
  EXPECT_EQ(response->points(0).rank(), 0u);
  EXPECT_DOUBLE_EQ(response->points(0).saliency(), 1.0);
  EXPECT_FLOAT_EQ(response->points(0).point().z(), 0.9f);
  EXPECT_EQ(response->points(1).rank(), 1u);
  EXPECT_TRUE(std::isnan(response->points(1).point().x()));
  EXPECT_FLOAT_EQ(response->support_plane().normal().y(), -1.0f);
  EXPECT_FLOAT_EQ(response->support_plane().d(), 0.7f);
  EXPECT_EQ(response->support_plane().inlier_count(), 1234u);
  ASSERT_EQ(response->timings_size(), 2);
  EXPECT_EQ(response->timings(1).stage(), "saliency.rso");
  EXPECT_DOUBLE_EQ(response->timings(1).seconds(), 0.002);
  EXPECT_EQ(response->maps_size(), 0);  // not asked for
}

TEST(ToDetectResponseTest, MapsAreSixteenBitPngsWhenAsked) {
  v1::DetectRequest request;
  request.mutable_options()->set_return_saliency_map(true);
  request.mutable_options()->set_return_channel_maps(true);
  absl::StatusOr<v1::DetectResponse> response =
      ToDetectResponse(SmallResult(), request);
  ASSERT_TRUE(response.ok()) << response.status();
  ASSERT_EQ(response->maps_size(), 2);
  EXPECT_EQ(response->maps(0).name(), "master");
  EXPECT_EQ(response->maps(1).name(), "rso");
  const v1::Image& image = response->maps(0).image();
  EXPECT_EQ(image.width(), 4u);
  EXPECT_EQ(image.height(), 2u);
  const std::string& png = image.compressed();
  const cv::Mat decoded = cv::imdecode(
      std::vector<uchar>(png.begin(), png.end()), cv::IMREAD_UNCHANGED);
  ASSERT_EQ(decoded.type(), CV_16UC1);
  EXPECT_EQ(decoded.at<uint16_t>(1, 3), 65535);
  EXPECT_EQ(decoded.at<uint16_t>(0, 1), 32768);  // round(0.5 * 65535)
  EXPECT_EQ(decoded.at<uint16_t>(0, 2), 0);      // NaN
  EXPECT_EQ(decoded.at<uint16_t>(1, 0), 65535);  // 1.5 clamped
  EXPECT_EQ(decoded.at<uint16_t>(0, 0), 0);
}

TEST(EncodeSaliencyPngTest, RefusesAMapOfAnotherType) {
  EXPECT_EQ(EncodeSaliencyPng(cv::Mat(2, 2, CV_8UC1)).status().code(),
            absl::StatusCode::kInternal);
  EXPECT_EQ(EncodeSaliencyPng(cv::Mat()).status().code(),
            absl::StatusCode::kInternal);
}

// COCO RLE by its definition: every pixel down each column in turn, a new
// run at each change, starting with zeros.
std::vector<uint32_t> RunsPixelByPixel(const cv::Mat& mask) {
  std::vector<uint32_t> runs;
  bool inside = false;
  uint32_t run = 0;
  for (int u = 0; u < mask.cols; ++u) {
    for (int v = 0; v < mask.rows; ++v) {
      const bool here = mask.at<unsigned char>(v, u) != 0;
      if (here != inside) {
        runs.push_back(run);
        run = 0;
        inside = here;
      }
      ++run;
    }
  }
  if (!mask.empty()) runs.push_back(run);
  return runs;
}

std::vector<uint32_t> Counts(const v1::RleMask& rle) {
  return {rle.counts().begin(), rle.counts().end()};
}

TEST(ToRleMaskTest, RunsAreThoseOfEveryPixelDownEachColumn) {
  // Objects touching each border of the frame, its corners, the bottom of
  // their own box in some columns, and masks of one pixel: the runs that
  // cross from a column into the next, and the box's edges, are where a
  // reader of the box alone could go wrong.
  std::vector<cv::Mat> masks;
  const auto blank = [] { return cv::Mat(48, 64, CV_8UC1, cv::Scalar(0)); };
  masks.push_back(blank());                                    // nothing
  masks.push_back(cv::Mat(48, 64, CV_8UC1, cv::Scalar(255)));  // all
  for (const cv::Point corner : {cv::Point(0, 0), cv::Point(63, 0),
                                 cv::Point(0, 47), cv::Point(63, 47)}) {
    cv::Mat one = blank();
    one.at<unsigned char>(corner) = 1;
    masks.push_back(one);
  }
  cv::Mat left = blank();
  left(cv::Rect(0, 10, 5, 20)).setTo(1);  // on the left border
  masks.push_back(left);
  cv::Mat bottom = blank();
  bottom(cv::Rect(20, 30, 9, 18)).setTo(7);  // down to the last row
  masks.push_back(bottom);
  cv::Mat top_right = blank();
  top_right(cv::Rect(50, 0, 14, 6)).setTo(255);
  masks.push_back(top_right);
  cv::Mat two = blank();  // two parts: the box spans a gap
  cv::circle(two, {15, 15}, 6, cv::Scalar(255), cv::FILLED);
  cv::circle(two, {45, 35}, 8, cv::Scalar(255), cv::FILLED);
  masks.push_back(two);
  cv::Mat ring = blank();  // holes inside the box
  cv::circle(ring, {32, 24}, 12, cv::Scalar(255), 3);
  masks.push_back(ring);
  cv::RNG rng(17);
  for (int i = 0; i < 20; ++i) {
    cv::Mat noise(48, 64, CV_8UC1);
    rng.fill(noise, cv::RNG::UNIFORM, 0, 2);
    masks.push_back(noise);
  }
  // A view into a larger image (rows not contiguous).
  cv::Mat larger(60, 80, CV_8UC1, cv::Scalar(0));
  cv::circle(larger, {40, 30}, 10, cv::Scalar(255), cv::FILLED);
  masks.push_back(larger(cv::Rect(30, 20, 40, 30)));
  for (size_t i = 0; i < masks.size(); ++i) {
    SCOPED_TRACE(i);
    const v1::RleMask rle = ToRleMask(masks[i]);
    EXPECT_EQ(rle.height(), static_cast<uint32_t>(masks[i].rows));
    EXPECT_EQ(rle.width(), static_cast<uint32_t>(masks[i].cols));
    EXPECT_EQ(Counts(rle), RunsPixelByPixel(masks[i]));
  }
}

TEST(ToRleMaskTest, AMaskWithoutPixelsHasNoRuns) {
  const v1::RleMask rle = ToRleMask(cv::Mat(0, 0, CV_8UC1));
  EXPECT_EQ(rle.height(), 0u);
  EXPECT_EQ(rle.width(), 0u);
  EXPECT_EQ(rle.counts_size(), 0);
}

TEST(CapabilitiesTest, ListWhatCoreValidates) {
  const v1::GetCapabilitiesResponse capabilities =
      BuildCapabilities(FrameLimits(), 1000);
  std::vector<int> ops(capabilities.saliency_operators().begin(),
                       capabilities.saliency_operators().end());
  // Every operator; each one listed passes core's Validate.
  EXPECT_THAT(ops,
              ::testing::IsSupersetOf(
                  {v1::SALIENCY_OPERATOR_PH, v1::SALIENCY_OPERATOR_SH,
                   v1::SALIENCY_OPERATOR_RSO, v1::SALIENCY_OPERATOR_SYM3D,
                   v1::SALIENCY_OPERATOR_ITTI, v1::SALIENCY_OPERATOR_HAREL,
                   v1::SALIENCY_OPERATOR_HOU, v1::SALIENCY_OPERATOR_KOOTSTRA}));
  for (int op : ops) {
    v1::DetectOptions options;
    options.add_saliency()->set_op(static_cast<v1::SaliencyOperator>(op));
    // The top-down cues need their cue.
    for (int c : {250, 200, 10}) options.add_target_color_rgb(c);
    options.mutable_location_prior()->set_u(10);
    EXPECT_TRUE(ToDetectOptions(options).ok()) << op;
  }
  EXPECT_THAT(capabilities.pyramids(), ::testing::Contains(v1::PYRAMID_NONE));
  EXPECT_THAT(capabilities.normalizations(),
              ::testing::Contains(v1::NORMALIZATION_LIN));
  EXPECT_THAT(capabilities.extractions(),
              ::testing::Contains(v1::EXTRACTION_MSR));
  EXPECT_EQ(capabilities.max_width(), FrameLimits().max_width);
  EXPECT_EQ(capabilities.max_message_bytes(), 1000u);
  EXPECT_THAT(capabilities.compressed_formats(),
              ::testing::ElementsAre("png", "jpeg"));
  EXPECT_FALSE(capabilities.server_version().empty());
}

}  // namespace
}  // namespace fovea::server
