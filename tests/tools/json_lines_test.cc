// The --json lines of fovea-eval parse as JSON whatever the values are.

#include "tools/eval/json_lines.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <limits>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace fovea::eval {
namespace {

using ::testing::ElementsAreArray;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

// `line` parsed, keys in the order written; a parse error fails the test
// with the line.
nlohmann::ordered_json Parsed(const std::string& line) {
  EXPECT_EQ(line.find('\n'), std::string::npos) << line;
  EXPECT_TRUE(nlohmann::ordered_json::accept(line)) << line;
  return nlohmann::ordered_json::parse(line, /*cb=*/nullptr,
                                       /*allow_exceptions=*/false);
}

std::vector<std::string> KeysOf(const nlohmann::ordered_json& json) {
  std::vector<std::string> keys;
  for (const auto& [key, value] : json.items()) keys.push_back(key);
  return keys;
}

TEST(JsonLinesTest, DetectWritesNonFiniteNumbersAsNull) {
  DetectEvalSummary summary;
  summary.scenes.resize(3);
  summary.hit_ratio = kNaN;
  summary.distance_to_center = kInf;
  summary.distance_to_center_thesis = -kInf;
  summary.hit_ratio_at.fill(0.5);
  summary.hit_ratio_at[0] = kNaN;
  summary.detect_ms_median = 12.3456789;
  DetectEvalSummary many;  // no scene of ten objects: its mean is NaN
  many.hit_ratio = kNaN;

  const nlohmann::ordered_json json = Parsed(DetectSummaryJson(summary, many));
  ASSERT_TRUE(json.is_object());
  EXPECT_EQ(json["scenes"], 3);
  EXPECT_TRUE(json["hit_ratio"].is_null());
  EXPECT_TRUE(json["distance_to_center"].is_null());
  EXPECT_TRUE(json["distance_to_center_thesis"].is_null());
  ASSERT_EQ(json["hit_ratio_at"].size(), summary.hit_ratio_at.size());
  EXPECT_TRUE(json["hit_ratio_at"][0].is_null());
  EXPECT_EQ(json["hit_ratio_at"][1], 0.5);
  EXPECT_EQ(json["scenes_10plus"], 0);
  EXPECT_TRUE(json["hit_ratio_10plus"].is_null());
  EXPECT_EQ(json["repeated_points"], 0.0);
  // Six significant digits, as absl::StrCat printed them.
  EXPECT_EQ(json["detect_ms_median"], 12.3457);
  EXPECT_THAT(
      KeysOf(json),
      ElementsAreArray({"scenes", "hit_ratio", "hit_ratio_all_points",
                        "distance_to_center", "distance_to_center_thesis",
                        "hit_ratio_at", "scenes_10plus", "hit_ratio_10plus",
                        "repeated_points", "off_object_points",
                        "detect_ms_median"}));
}

TEST(JsonLinesTest, MethodKeepsItsKeysAndRoundingAndNullsNonFinite) {
  MethodSummary summary;
  summary.method = "cos";
  summary.scenes = 45;
  summary.f_all = 0.123456;
  summary.f_best = kNaN;
  summary.overlap_f = -kInf;
  summary.first_ms_median = 63.27;
  summary.total_ms_median = kInf;

  const nlohmann::ordered_json json =
      Parsed(MethodSummaryJson(summary, /*cross_validated=*/true, 5));
  EXPECT_EQ(json["method"], "cos");
  EXPECT_EQ(json["evaluation"], "cross-validated");
  EXPECT_EQ(json["folds"], 5);
  EXPECT_EQ(json["scenes"], 45);
  EXPECT_EQ(json["f_all"], 0.1235);  // 4 decimals
  EXPECT_TRUE(json["f_best"].is_null());
  EXPECT_TRUE(json["overlap_f"].is_null());
  EXPECT_EQ(json["first_mask_ms_median"], 63.3);  // 1 decimal
  EXPECT_TRUE(json["all_masks_ms_median"].is_null());
  EXPECT_THAT(
      KeysOf(json),
      ElementsAreArray({"method", "evaluation", "folds", "scenes", "f_all",
                        "f_best", "f_first", "object_recall", "false_masks",
                        "whole_scene_f", "overlap_p", "overlap_r", "overlap_f",
                        "boundary_p", "boundary_r", "boundary_f", "objects_075",
                        "first_mask_ms_median", "all_masks_ms_median"}));

  const nlohmann::ordered_json held_out =
      Parsed(MethodSummaryJson(summary, /*cross_validated=*/false, 5));
  EXPECT_EQ(held_out["evaluation"], "held-out");
  EXPECT_EQ(held_out["folds"], 0);
}

TEST(JsonLinesTest, IncRoomAndRawWriteNonFiniteNumbersAsNull) {
  IncEvalSummary inc;
  inc.scenes.resize(2);
  inc.f_all = kNaN;
  inc.whole_scene_f = kInf;
  const nlohmann::ordered_json inc_json = Parsed(IncSummaryJson(inc));
  EXPECT_EQ(inc_json["scenes"], 2);
  EXPECT_TRUE(inc_json["f_all"].is_null());
  EXPECT_TRUE(inc_json["whole_scene_f"].is_null());
  EXPECT_THAT(
      KeysOf(inc_json),
      ElementsAreArray({"scenes", "f_all", "f_best", "f_first", "object_recall",
                        "false_masks", "whole_scene_f"}));

  RoomSummary room;  // group "" is all rooms
  room.rooms = 0;
  room.object_recall = kNaN;  // no objects at all
  room.first_ms_median = -kInf;
  const nlohmann::ordered_json room_json = Parsed(RoomSummaryJson(room));
  EXPECT_EQ(room_json["group"], "all");
  EXPECT_EQ(room_json["rooms"], 0);
  EXPECT_TRUE(room_json["object_recall"].is_null());
  EXPECT_TRUE(room_json["first_ms_median"].is_null());
  EXPECT_EQ(room_json["support_correct"], 0.0);
  EXPECT_EQ(KeysOf(room_json).size(), 13u);

  RawFrameScore raw;
  raw.masks = 4;
  raw.precision = kNaN;  // no mask pixels
  raw.recall = 0.98765;
  raw.uois.overlap_f = kInf;
  const nlohmann::ordered_json raw_json =
      Parsed(RawFrameJson("learn6", "raw", raw));
  EXPECT_EQ(raw_json["scene"], "learn6");
  EXPECT_EQ(raw_json["frame"], "raw");
  EXPECT_EQ(raw_json["masks"], 4);
  EXPECT_TRUE(raw_json["precision"].is_null());
  EXPECT_EQ(raw_json["recall"], 0.9877);
  EXPECT_TRUE(raw_json["overlap_f"].is_null());
}

TEST(JsonLinesTest, NamesAreEscapedAndBytesThatAreNotUtf8Replaced) {
  // A scene's name is its file's: quotes, backslashes, control characters
  // and stray bytes are all possible.
  const std::string name = "we\"ird\\scene\t\x01\xff";
  const nlohmann::ordered_json json =
      Parsed(RawFrameJson(name, "cropped", RawFrameScore{}));
  EXPECT_EQ(json["scene"], "we\"ird\\scene\t\x01\xEF\xBF\xBD");  // U+FFFD

  RoomSummary room;
  room.group = "kinect_v1 \"640x480\"";
  EXPECT_EQ(Parsed(RoomSummaryJson(room))["group"], room.group);
}

}  // namespace
}  // namespace fovea::eval
