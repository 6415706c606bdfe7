// The identity figures of fovea-eval track on hand-made frames whose
// answer can be counted by hand.

#include "tools/eval/track_eval.h"

#include <gtest/gtest.h>

#include <string>
#include <utility>
#include <vector>

namespace fovea::eval {
namespace {

// A frame's identities: truths, tracks and the matched (truth, track) pairs.
FrameIdentities Frame(int truths, int tracks,
                      std::vector<std::pair<int, int>> matched) {
  FrameIdentities f;
  f.truths = truths;
  f.tracks = tracks;
  f.matched = std::move(matched);
  return f;
}

TEST(CountIdentities, AFlawlessSequenceScoresOne) {
  // Two objects, tracks 7 and 9, matched in all three frames.
  std::vector<FrameIdentities> frames(3, Frame(2, 2, {{0, 7}, {1, 9}}));
  const IdentityCounts c = CountIdentities(frames);
  EXPECT_EQ(c.idtp, 6);
  EXPECT_EQ(c.idfp, 0);
  EXPECT_EQ(c.idfn, 0);
  EXPECT_EQ(c.switches, 0);
  EXPECT_EQ(c.truth_frames, 6);
  EXPECT_DOUBLE_EQ(Idf1(c), 1.0);
}

TEST(CountIdentities, ASwitchCostsTheFramesAfterItAndCountsOnce) {
  // Object 0 is track 1 for two frames, then track 2 for two frames.
  std::vector<FrameIdentities> frames = {
      Frame(1, 1, {{0, 1}}), Frame(1, 1, {{0, 1}}), Frame(1, 1, {{0, 2}}),
      Frame(1, 1, {{0, 2}})};
  const IdentityCounts c = CountIdentities(frames);
  EXPECT_EQ(c.switches, 1);
  // One identity pairing keeps 2 of the 4 frames: IDTP 2, IDFN 2, IDFP 2.
  EXPECT_EQ(c.idtp, 2);
  EXPECT_EQ(c.idfn, 2);
  EXPECT_EQ(c.idfp, 2);
  EXPECT_DOUBLE_EQ(Idf1(c), 0.5);
}

TEST(CountIdentities, MissesAndExtraTracksLowerIdf1WithoutSwitches) {
  // One object seen in 2 frames, found in 1; a stray track in frame 2.
  std::vector<FrameIdentities> frames = {Frame(1, 1, {{0, 4}}),
                                         Frame(1, 1, {})};
  const IdentityCounts c = CountIdentities(frames);
  EXPECT_EQ(c.switches, 0);
  EXPECT_EQ(c.idtp, 1);
  EXPECT_EQ(c.idfn, 1);
  EXPECT_EQ(c.idfp, 1);
  EXPECT_DOUBLE_EQ(Idf1(c), 0.5);
  EXPECT_DOUBLE_EQ(Idf1(IdentityCounts{}), 1.0);
}

TEST(MatchFrame, AMaskMatchesTheObjectItCoversAtIouOneHalf) {
  synth::SequenceFrame frame;
  frame.frame.labels = cv::Mat(10, 10, CV_32SC1, cv::Scalar(1));
  frame.frame.labels(cv::Rect(0, 0, 4, 5)).setTo(20);   // object id 3, 20 px
  frame.frame.labels(cv::Rect(6, 0, 4, 10)).setTo(30);  // object id 5, 40 px
  frame.object_ids = {3, 5};
  TrackedObject good;  // 20 of object 3's pixels and 4 more: IoU 20/24
  good.track_id = 11;
  good.object.mask = cv::Mat(10, 10, CV_8UC1, cv::Scalar(0));
  good.object.mask(cv::Rect(0, 0, 4, 6)).setTo(255);
  TrackedObject half;  // 16 of object 5's 40 pixels: IoU 0.4, no match
  half.track_id = 12;
  half.object.mask = cv::Mat(10, 10, CV_8UC1, cv::Scalar(0));
  half.object.mask(cv::Rect(6, 0, 4, 4)).setTo(255);
  TrackedObject gone;
  gone.track_id = 13;
  gone.state = TrackState::kGone;
  const FrameIdentities f = MatchFrame(frame, {good, half, gone}, 10);
  EXPECT_EQ(f.truths, 2);
  EXPECT_EQ(f.tracks, 2);  // the gone track has no mask
  ASSERT_EQ(f.matched.size(), 1u);
  EXPECT_EQ(f.matched[0], std::make_pair(3, 11));
  // The half mask is named with the object it lies on: all 16 of its
  // pixels on object 5 (its sequence id), IoU 16/40.
  EXPECT_EQ(f.unmatched,
            std::vector<std::string>{"track 12 16 px, 1.00 on 5 (IoU 0.40)"});
}

TEST(MatchFrame, AMaskOfAnObjectTooSmallToCountIsIgnored) {
  synth::SequenceFrame frame;
  frame.frame.labels = cv::Mat(10, 10, CV_32SC1, cv::Scalar(1));
  frame.frame.labels(cv::Rect(0, 0, 5, 4)).setTo(20);  // 20 px: counts
  frame.frame.labels(cv::Rect(8, 8, 2, 2)).setTo(30);  // 4 px: too small
  frame.object_ids = {0, 1};
  TrackedObject sliver;  // the small object's 4 pixels and 2 more
  sliver.track_id = 2;
  sliver.object.mask = cv::Mat(10, 10, CV_8UC1, cv::Scalar(0));
  sliver.object.mask(cv::Rect(7, 8, 3, 2)).setTo(255);
  TrackedObject stray;  // table only: a false track
  stray.track_id = 3;
  stray.object.mask = cv::Mat(10, 10, CV_8UC1, cv::Scalar(0));
  stray.object.mask(cv::Rect(0, 6, 4, 2)).setTo(255);
  const FrameIdentities f = MatchFrame(frame, {sliver, stray}, 10);
  EXPECT_EQ(f.truths, 1);
  EXPECT_EQ(f.tracks, 1);  // the stray; the sliver is neither
  EXPECT_TRUE(f.matched.empty());
  EXPECT_EQ(f.unmatched,
            std::vector<std::string>{"track 3 8 px, 0.00 on 0 (IoU 0.00)"});
}

TEST(ChangedTruths, WhatMovedOrAppearedAndNotWhatLostPixels) {
  synth::SequenceFrame before;
  before.frame.labels = cv::Mat(40, 60, CV_32SC1, cv::Scalar(1));
  before.frame.labels(cv::Rect(2, 2, 16, 16)).setTo(20);   // id 7
  before.frame.labels(cv::Rect(30, 2, 16, 16)).setTo(30);  // id 8
  before.object_ids = {7, 8};
  synth::SequenceFrame now = before;
  now.frame.labels = before.frame.labels.clone();
  // id 7 loses a few scattered pixels (dropouts); id 8 moves 6 pixels down.
  for (int i = 0; i < 16; i += 3) now.frame.labels.at<int>(2 + i, 2 + i) = 0;
  now.frame.labels(cv::Rect(30, 2, 16, 16)).setTo(1);
  now.frame.labels(cv::Rect(30, 8, 16, 16)).setTo(30);
  std::vector<cv::Mat> changed = ChangedTruths(before, now, 100);
  ASSERT_EQ(changed.size(), 1u);
  EXPECT_EQ(cv::countNonZero(changed[0] != (now.frame.labels == 30)), 0);
  // A third object appears: changed too.
  now.frame.labels(cv::Rect(2, 22, 16, 16)).setTo(40);
  now.object_ids = {7, 8, 9};
  EXPECT_EQ(ChangedTruths(before, now, 100).size(), 2u);
  // All of them moved (the camera did): none stands out.
  synth::SequenceFrame shifted = before;
  shifted.frame.labels = cv::Mat(40, 60, CV_32SC1, cv::Scalar(1));
  shifted.frame.labels(cv::Rect(2, 12, 16, 16)).setTo(20);
  shifted.frame.labels(cv::Rect(30, 12, 16, 16)).setTo(30);
  EXPECT_TRUE(ChangedTruths(before, shifted, 100).empty());
}

TEST(TotalCost, CountsTheFewFullCutsTheMedianHides) {
  // Three cheap frames and one full cut: the median frame costs 1/50 of a
  // fresh call, the stream (1 + 1 + 1 + 100) / (50 + 50 + 50 + 100).
  EXPECT_DOUBLE_EQ(TotalCost({1, 1, 1, 100}, {50, 50, 50, 100}), 0.412);
  EXPECT_DOUBLE_EQ(TotalCost({1, 2}, {}), 0.0);
}

}  // namespace
}  // namespace fovea::eval
