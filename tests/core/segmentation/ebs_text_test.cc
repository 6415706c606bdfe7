#include <gtest/gtest.h>

#include <array>
#include <optional>
#include <random>
#include <regex>
#include <string>

#include "core/frame/organized_cloud.h"
#include "core/segmentation/ebs.h"
#include "core/synth/synth_scene.h"
#include "tests/core/testing/scenes.h"

// The text form of EbsModel (core/segmentation/ebs_text.cc).

namespace fovea {
namespace {

// Histograms of the options' bins with random counts from `seed`, every
// bin of both sides at least 1.
std::array<EbsModel::Cue, EbsModel::kCues> Counts(
    const EbsTrainOptions& options, uint32_t seed) {
  std::mt19937 random(seed);
  std::array<EbsModel::Cue, EbsModel::kCues> cues;
  const CueBins* bins[] = {&options.color_bins, &options.depth_bins,
                           &options.curvature_bins};
  for (int c = 0; c < EbsModel::kCues; ++c) {
    cues[c].bins = *bins[c];
    for (int i = 0; i < bins[c]->bins; ++i) {
      cues[c].edge.push_back(1 + random() % 1000);
      cues[c].no_edge.push_back(1 + random() % 100000);
    }
  }
  return cues;
}

// A model of made-up counts with the default options: the text form does
// not care where the counts came from.
class EbsTextTest : public ::testing::Test {
 protected:
  void SetUp() override {
    absl::StatusOr<EbsModel> model =
        EbsModel::FromCounts(EbsTrainOptions{}, Counts(EbsTrainOptions{}, 5));
    ASSERT_TRUE(model.ok()) << model.status();
    model_.emplace(*std::move(model));
  }

  std::optional<EbsModel> model_;
};

TEST_F(EbsTextTest, SerializeParseRoundTripGivesTheIdenticalMap) {
  const std::string text = model_->Serialize();
  absl::StatusOr<EbsModel> parsed = EbsModel::Parse(text);
  ASSERT_TRUE(parsed.ok()) << parsed.status();
  EXPECT_EQ(parsed->Serialize(), text);
  EXPECT_EQ(parsed->Version(), model_->Version());
  const synth::SynthScene scene =
      testing::BoxOnTable(Eigen::Vector3f(0.08f, 0.06f, 0.05f));
  absl::StatusOr<OrganizedCloud> cloud =
      BuildOrganizedCloud(scene.frame.frame, {});
  ASSERT_TRUE(cloud.ok()) << cloud.status();
  const cv::Mat a = model_->EdgeProbability(*cloud);
  const cv::Mat b = parsed->EdgeProbability(*cloud);
  ASSERT_EQ(a.size(), b.size());
  EXPECT_EQ(cv::norm(a, b, cv::NORM_INF), 0.0);
}

// Options other than the defaults survive the round trip (floats to the
// last bit).
TEST(EbsTextRoundTripTest, KeepsEveryOption) {
  EbsTrainOptions options;
  options.edge_maps.color_blur_sigma_px = 0.1f + 1e-7f;
  options.edge_maps.sobel_aperture = 5;
  options.edge_maps.depth_radius_px = 3;
  options.edge_maps.curvature_radius_px = 5;
  options.edge_maps.signed_curvature = false;
  options.normals.baseline_m = 0.0123456789f;
  options.normals.max_half_window = 7;
  options.normals.smoothing_half_window = 1;
  options.normals.max_depth_change_factor = 0.03f;
  options.boundary_band_px = 1;
  options.ignore_band_px = 3;
  options.color_bins = {8, 77.7f, false};
  options.depth_bins = {5, 0.3f, false};
  options.curvature_bins = {6, 1.5f, false};
  absl::StatusOr<EbsModel> model =
      EbsModel::FromCounts(options, Counts(options, 1));
  ASSERT_TRUE(model.ok()) << model.status();
  absl::StatusOr<EbsModel> parsed = EbsModel::Parse(model->Serialize());
  ASSERT_TRUE(parsed.ok()) << parsed.status();
  const EbsTrainOptions& o = parsed->options();
  EXPECT_EQ(o.edge_maps.color_blur_sigma_px,
            options.edge_maps.color_blur_sigma_px);
  EXPECT_EQ(o.edge_maps.sobel_aperture, 5);
  EXPECT_EQ(o.edge_maps.depth_radius_px, 3);
  EXPECT_EQ(o.edge_maps.curvature_radius_px, 5);
  EXPECT_FALSE(o.edge_maps.signed_curvature);
  EXPECT_EQ(o.normals.baseline_m, options.normals.baseline_m);
  EXPECT_EQ(o.normals.min_half_window, options.normals.min_half_window);
  EXPECT_EQ(o.normals.max_half_window, 7);
  EXPECT_EQ(o.normals.smoothing_half_window, 1);
  EXPECT_EQ(o.normals.max_depth_change_factor, 0.03f);
  EXPECT_EQ(o.boundary_band_px, 1);
  EXPECT_EQ(o.ignore_band_px, 3);
  EXPECT_EQ(o.color_bins.bins, 8);
  EXPECT_EQ(o.color_bins.max_value, 77.7f);
  EXPECT_EQ(o.depth_bins.bins, 5);
  EXPECT_FALSE(o.curvature_bins.signed_cue);
  for (int c = 0; c < EbsModel::kCues; ++c) {
    EXPECT_EQ(parsed->cues()[c].edge, model->cues()[c].edge);
    EXPECT_EQ(parsed->cues()[c].no_edge, model->cues()[c].no_edge);
  }
}

TEST_F(EbsTextTest, TextStartsWithMagicAndVersion) {
  const std::string text = model_->Serialize();
  EXPECT_EQ(text.rfind("fovea-ebs-model\nversion 1\n", 0), 0u) << text;
}

TEST_F(EbsTextTest, VersionNamesTheContent) {
  EXPECT_TRUE(
      std::regex_match(model_->Version(), std::regex("ebs-v1-[0-9a-f]{8}")))
      << model_->Version();
  std::array<EbsModel::Cue, EbsModel::kCues> cues = model_->cues();
  ++cues[0].edge[0];
  absl::StatusOr<EbsModel> other =
      EbsModel::FromCounts(model_->options(), cues);
  ASSERT_TRUE(other.ok()) << other.status();
  EXPECT_NE(other->Version(), model_->Version());
}

// Replaces the first line after the first that starts with `keyword` by
// `replacement`.
std::string ReplaceLine(const std::string& text, const std::string& keyword,
                        const std::string& replacement) {
  const size_t at = text.find("\n" + keyword) + 1;
  const size_t end = text.find('\n', at);
  return text.substr(0, at) + replacement + text.substr(end);
}

void ExpectRejected(const std::string& text, const std::string& what) {
  absl::StatusOr<EbsModel> parsed = EbsModel::Parse(text);
  ASSERT_FALSE(parsed.ok()) << "accepted " << what;
  EXPECT_EQ(parsed.status().code(), absl::StatusCode::kInvalidArgument) << what;
  EXPECT_FALSE(parsed.status().message().empty()) << what;
}

TEST_F(EbsTextTest, ParseRejectsCorruptText) {
  const std::string text = model_->Serialize();
  ExpectRejected("", "empty text");
  ExpectRejected("fovea-ebs-mode\n" + text.substr(text.find('\n') + 1),
                 "a wrong magic line");
  ExpectRejected("P6\n640 480\n255\n", "another format");
  ExpectRejected(ReplaceLine(text, "version", "version 2"), "version 2");
  ExpectRejected(text + "trailing\n", "text after end");

  // Histograms: the first count of the first "edge" line replaced.
  const size_t edge = text.find("\nedge ") + 6;
  const size_t edge_end = text.find(' ', edge);
  const auto with_first_count = [&](const std::string& count) {
    return text.substr(0, edge) + count + text.substr(edge_end);
  };
  const std::string nan_count = with_first_count("nan");
  ExpectRejected(nan_count, "a NaN count");
  EXPECT_NE(EbsModel::Parse(nan_count).status().message().find("whole number"),
            absl::string_view::npos);
  for (const std::string negative : {"-5", "-0"}) {
    ExpectRejected(with_first_count(negative), "count " + negative);
    EXPECT_NE(EbsModel::Parse(with_first_count(negative))
                  .status()
                  .message()
                  .find("negative"),
              absl::string_view::npos);
  }
  ExpectRejected(with_first_count("+5"), "a count with a sign");
  ExpectRejected(with_first_count("5.5"), "a fractional count");
  ExpectRejected(with_first_count("99999999999999999999"),
                 "a count past 64 bits");
  std::string short_line = text;
  short_line.erase(edge, edge_end - edge + 1);
  ExpectRejected(short_line, "a histogram one count short");
  EXPECT_NE(EbsModel::Parse(short_line).status().message().find("counts"),
            absl::string_view::npos);
  ExpectRejected(ReplaceLine(text, "cue color",
                             "cue color bins 31 max_value 100 signed 0"),
                 "a bin count that does not match the histogram");
  ExpectRejected(
      ReplaceLine(text, "cue color", "cue color bins 32 max_value -1 signed 0"),
      "a negative bin range");
  ExpectRejected(
      ReplaceLine(text, "cue color", "cue color bins 0 max_value 100 signed 0"),
      "zero bins");
  ExpectRejected(
      ReplaceLine(text, "edge ", "edge" + std::string(32, ' ') + "0"),
      "blank counts");
  std::string all_zero = "edge";
  for (int i = 0; i < 32; ++i) all_zero += " 0";
  ExpectRejected(ReplaceLine(text, "edge ", all_zero), "an empty histogram");

  // Options.
  ExpectRejected(ReplaceLine(text, "edge_maps",
                             "edge_maps color_blur_sigma_px 1 sobel_aperture 4 "
                             "depth_radius_px 2 curvature_radius_px 6 "
                             "signed_curvature 1"),
                 "an invalid Sobel aperture");
  ExpectRejected(ReplaceLine(text, "edge_maps",
                             "edge_maps color_blur_sigma_px nan "
                             "sobel_aperture 3 depth_radius_px 2 "
                             "curvature_radius_px 6 signed_curvature 1"),
                 "a NaN option");
  ExpectRejected(ReplaceLine(text, "labels", "labels boundary_band_px 2"),
                 "a missing option");
}

TEST_F(EbsTextTest, ParseRejectsEveryTruncation) {
  const std::string text = model_->Serialize();
  // Everything short of "end" (with or without its newline) is truncated.
  for (size_t n = 0; n + 1 < text.size(); ++n) {
    absl::StatusOr<EbsModel> parsed = EbsModel::Parse(text.substr(0, n));
    ASSERT_FALSE(parsed.ok()) << "accepted the first " << n << " bytes";
    ASSERT_EQ(parsed.status().code(), absl::StatusCode::kInvalidArgument);
  }
  EXPECT_TRUE(EbsModel::Parse(text.substr(0, text.size() - 1)).ok());
}

// Random byte edits of a valid text: each parses to a model or to
// INVALID_ARGUMENT, never to a crash (run under a sanitizer to see more).
TEST_F(EbsTextTest, ParseSurvivesRandomEdits) {
  const std::string text = model_->Serialize();
  std::mt19937 random(7);
  std::string alphabet = "0123456789 -.\nenaxX";
  alphabet += '\0';
  alphabet += '\xff';
  int accepted = 0;
  for (int trial = 0; trial < 3000; ++trial) {
    std::string edited = text;
    const int edits = 1 + static_cast<int>(random() % 4);
    for (int e = 0; e < edits; ++e) {
      const size_t at = random() % edited.size();
      const char c = alphabet[random() % alphabet.size()];
      switch (random() % 3) {
        case 0:
          edited[at] = c;
          break;
        case 1:
          edited.insert(at, 1, c);
          break;
        default:
          edited.erase(at, 1);
      }
    }
    absl::StatusOr<EbsModel> parsed = EbsModel::Parse(edited);
    if (parsed.ok()) {
      ++accepted;
      // Whatever parses is a usable model.
      EXPECT_FALSE(parsed->Version().empty());
    } else {
      ASSERT_EQ(parsed.status().code(), absl::StatusCode::kInvalidArgument);
    }
  }
  // Most edits of digits still parse; the test must have seen both.
  EXPECT_GT(accepted, 0);
  EXPECT_LT(accepted, 3000);
}

TEST(EbsFromCountsTest, RejectsMalformedHistograms) {
  const EbsTrainOptions options;
  std::array<EbsModel::Cue, EbsModel::kCues> cues = Counts(options, 1);
  cues[1].edge.pop_back();
  EXPECT_EQ(EbsModel::FromCounts(options, cues).status().code(),
            absl::StatusCode::kInvalidArgument);
  cues = Counts(options, 1);
  cues[2].no_edge[3] = -1;
  EXPECT_NE(
      EbsModel::FromCounts(options, cues).status().message().find("negative"),
      absl::string_view::npos);
  cues = Counts(options, 1);
  std::fill(cues[0].edge.begin(), cues[0].edge.end(), 0);
  EXPECT_NE(
      EbsModel::FromCounts(options, cues).status().message().find("no edge"),
      absl::string_view::npos);
  cues = Counts(options, 1);
  cues[0].edge[0] = int64_t{1} << 53;
  EXPECT_EQ(EbsModel::FromCounts(options, cues).status().code(),
            absl::StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace fovea
