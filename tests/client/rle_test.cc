#include "client/rle.h"

#include <cstdint>
#include <vector>

#include "gmock/gmock.h"
#include "gtest/gtest.h"

namespace fovea::client {
namespace {

using ::testing::ElementsAre;
using ::testing::ElementsAreArray;
using ::testing::HasSubstr;

fovea::v1::RleMask Rle(uint32_t height, uint32_t width,
                       std::vector<uint32_t> counts) {
  fovea::v1::RleMask rle;
  rle.set_height(height);
  rle.set_width(width);
  for (uint32_t c : counts) rle.add_counts(c);
  return rle;
}

TEST(DecodeRleTest, RunsGoDownColumnsStartingWithZeros) {
  // 2 rows x 3 columns; column-major order is (0,0) (1,0) (0,1) (1,1) ...
  // counts 1 zero, 2 ones, 3 zeros: pixels (row 1, col 0) and (row 0, col 1).
  absl::StatusOr<ByteMask> mask = DecodeRle(Rle(2, 3, {1, 2, 3}));
  ASSERT_TRUE(mask.ok()) << mask.status();
  EXPECT_EQ(mask->width, 3u);
  EXPECT_EQ(mask->height, 2u);
  EXPECT_THAT(mask->pixels, ElementsAre(0, 1, 0,  //
                                        1, 0, 0));
  EXPECT_EQ(mask->at(1, 0), 1);
  EXPECT_EQ(mask->at(0, 1), 1);
}

TEST(DecodeRleTest, MaskStartingWithOneHasLeadingZeroRun) {
  absl::StatusOr<ByteMask> mask = DecodeRle(Rle(2, 2, {0, 1, 2, 1}));
  ASSERT_TRUE(mask.ok()) << mask.status();
  EXPECT_THAT(mask->pixels, ElementsAre(1, 0,  //
                                        0, 1));
}

TEST(DecodeRleTest, EmptyAndFullMasks) {
  absl::StatusOr<ByteMask> empty = DecodeRle(Rle(3, 4, {12}));
  ASSERT_TRUE(empty.ok()) << empty.status();
  EXPECT_THAT(empty->pixels, ElementsAreArray(std::vector<uint8_t>(12, 0)));

  absl::StatusOr<ByteMask> full = DecodeRle(Rle(3, 4, {0, 12}));
  ASSERT_TRUE(full.ok()) << full.status();
  EXPECT_THAT(full->pixels, ElementsAreArray(std::vector<uint8_t>(12, 1)));

  absl::StatusOr<ByteMask> no_pixels = DecodeRle(Rle(0, 0, {}));
  ASSERT_TRUE(no_pixels.ok()) << no_pixels.status();
  EXPECT_TRUE(no_pixels->pixels.empty());
}

TEST(DecodeRleTest, RunsNotCoveringTheMaskAreRefused) {
  absl::StatusOr<ByteMask> short_runs = DecodeRle(Rle(2, 2, {1, 2}));
  ASSERT_EQ(short_runs.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(short_runs.status().message(), HasSubstr("counts"));
  EXPECT_EQ(DecodeRle(Rle(2, 2, {3, 2})).status().code(),
            absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(DecodeRle(Rle(2, 2, {})).status().code(),
            absl::StatusCode::kInvalidArgument);
}

TEST(EncodeRleTest, RoundTripsAndStartsWithZeros) {
  ByteMask mask;
  mask.width = 3;
  mask.height = 2;
  mask.pixels = {1, 1, 0,  //
                 0, 1, 1};
  absl::StatusOr<fovea::v1::RleMask> rle = EncodeRle(mask);
  ASSERT_TRUE(rle.ok()) << rle.status();
  // Column-major: 1 0 | 1 1 | 0 1 -> runs 0 zeros, 1 one, 1 zero, 2 ones,
  // 1 zero, 1 one, starting with zeros.
  EXPECT_THAT(rle->counts(), ElementsAre(0, 1, 1, 2, 1, 1));
  absl::StatusOr<ByteMask> back = DecodeRle(*rle);
  ASSERT_TRUE(back.ok()) << back.status();
  EXPECT_EQ(back->pixels, mask.pixels);
}

TEST(EncodeRleTest, WrongPixelCountIsRefused) {
  ByteMask mask;
  mask.width = 3;
  mask.height = 2;
  mask.pixels = {1, 0};
  EXPECT_EQ(EncodeRle(mask).status().code(),
            absl::StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace fovea::client
