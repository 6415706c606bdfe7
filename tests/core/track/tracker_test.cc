// The tracker on synthetic sequences with ground-truth identities: a still
// scene is segmented once and keeps its identities, and is cut again on the
// mean of its frames once they are enough, an object taken away is reported
// gone once, a drifting camera keeps every identity, an object put down
// elsewhere keeps its own, the support is kept while it fits, and a pushed
// object is cut again in the region around it while the rest is kept as it
// was. The rules on pieces are tested in tracker_pieces_test.cc.

#include "core/track/tracker.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <set>
#include <utility>
#include <vector>

#include "tests/core/track/tracker_testing.h"

namespace fovea::tracker_testing {
namespace {

TEST(Tracker, AStillSceneIsSegmentedOnceAndKeepsItsIdentities) {
  ASSERT_NE(Models(), nullptr);
  // Three frames: the fourth is refined (refine_first_frames).
  const Sequence sequence = GenerateSequence(SequenceKind::kStatic, 3, 3);
  std::vector<TrackedFrame> frames;
  const std::map<int, std::set<int>> tracks = Play(sequence, false, &frames);
  ASSERT_EQ(frames.size(), 3u);
  EXPECT_FALSE(frames[0].reused);
  ASSERT_FALSE(frames[0].objects.empty());
  for (size_t t = 1; t < frames.size(); ++t) {
    // Fresh sensor noise every frame is not a change.
    EXPECT_TRUE(frames[t].reused)
        << "frame " << t << " changed " << frames[t].changed_fraction;
    ASSERT_EQ(frames[t].objects.size(), frames[0].objects.size());
    for (size_t i = 0; i < frames[t].objects.size(); ++i) {
      EXPECT_EQ(frames[t].objects[i].state, TrackState::kKept);
      EXPECT_EQ(frames[t].objects[i].track_id, frames[0].objects[i].track_id);
    }
  }
  for (const auto& [truth, ids] : tracks) {
    EXPECT_EQ(ids.size(), 1u) << "object " << truth;
  }
}

// The mean over the ground-truth objects of `frame` of the best F of a
// mask of `tracked` on each.
double MeanBestF(const synth::SequenceFrame& frame,
                 const TrackedFrame& tracked) {
  double sum = 0.0;
  for (size_t k = 0; k < frame.object_ids.size(); ++k) {
    const cv::Mat truth = PixelsOfObject(frame, k);
    const double size = cv::countNonZero(truth);
    double best = 0.0;
    for (const TrackedObject& o : tracked.objects) {
      if (o.object.mask.empty()) continue;
      const double both = cv::countNonZero(o.object.mask & truth);
      best =
          std::max(best, 2.0 * both / (size + cv::countNonZero(o.object.mask)));
    }
    sum += best;
  }
  return frame.object_ids.empty()
             ? 1.0
             : sum / static_cast<double>(frame.object_ids.size());
}

TEST(Tracker, AStillSceneIsCutAgainOnceOnTheMeanOfItsFrames) {
  // Six unchanged frames in a row (a still period after the stream's first:
  // refine_first_frames 0): their mean is segmented at the sixth, once, and
  // the masks fit the objects better than the first frame's, whose noise
  // the mean averages down by sqrt(6).
  ASSERT_NE(Models(), nullptr);
  TrackerOptions options;
  options.refine_first_frames = 0;
  double first = 0.0;
  double refined = 0.0;
  for (const uint64_t seed : {1, 2, 3, 4}) {
    const Sequence sequence = GenerateSequence(SequenceKind::kStatic, seed, 9);
    std::vector<TrackedFrame> frames;
    const std::map<int, std::set<int>> tracks =
        Play(sequence, false, &frames, options);
    ASSERT_EQ(frames.size(), 9u);
    for (size_t t = 0; t < frames.size(); ++t) {
      EXPECT_EQ(frames[t].refined, t == 5) << "seed " << seed << " frame " << t;
      EXPECT_EQ(frames[t].reused, t != 0 && t != 5)
          << "seed " << seed << " frame " << t;
    }
    first += MeanBestF(sequence.frames[0], frames[0]);
    refined += MeanBestF(sequence.frames[8], frames[8]);
  }
  // Summed over the 4 scenes: 3.36 and 3.63 when this was written.
  EXPECT_GT(refined - first, 0.12) << first << " -> " << refined;
  // Off: cut once (refine_first_frames does not turn it on).
  TrackerOptions off;
  off.refine_frames = 0;
  std::vector<TrackedFrame> frames;
  Play(GenerateSequence(SequenceKind::kStatic, 1, 9), false, &frames, off);
  for (size_t t = 1; t < frames.size(); ++t) EXPECT_TRUE(frames[t].reused);
  off.refine_frames = 65;
  EXPECT_FALSE(Validate(off).ok());
  off.refine_frames = 1;
  EXPECT_FALSE(Validate(off).ok());
  off.refine_frames = 6;
  off.refine_first_frames = 1;
  EXPECT_FALSE(Validate(off).ok());
  off.refine_first_frames = 65;
  EXPECT_FALSE(Validate(off).ok());
}

TEST(Tracker, TheStreamsFirstStillPeriodIsRefinedSooner) {
  // Everything in view at the first still period comes from one frame's
  // cut: it is refined at its fourth frame (refine_first_frames 4). A
  // later still period (here, after the whole scene changed) waits six.
  ASSERT_NE(Models(), nullptr);
  const Sequence a = GenerateSequence(SequenceKind::kStatic, 1, 5);
  const Sequence b = GenerateSequence(SequenceKind::kStatic, 2, 7);
  ASSERT_EQ(a.frames[0].frame.frame.depth.size(),
            b.frames[0].frame.frame.depth.size());
  Tracker tracker(TrackerOptions{}, &*Models()->inc);
  std::vector<bool> refined;
  std::vector<bool> reused;
  for (const Sequence* s : {&a, &b}) {
    for (const synth::SequenceFrame& f : s->frames) {
      const absl::StatusOr<TrackedFrame> out =
          tracker.Process(f.frame.frame, std::nullopt);
      ASSERT_TRUE(out.ok()) << out.status();
      refined.push_back(out->refined);
      reused.push_back(out->reused);
    }
  }
  ASSERT_EQ(refined.size(), 12u);
  for (size_t t = 0; t < refined.size(); ++t) {
    EXPECT_EQ(refined[t], t == 3 || t == 10) << "frame " << t;
    EXPECT_EQ(reused[t], t != 0 && t != 3 && t != 5 && t != 10)
        << "frame " << t;
  }
}

TEST(Tracker, ARefinedCutThatFailsLeavesTheStillPeriodAsItWas) {
  // The fourth frame's refined cut (the stream's first still period) is
  // interrupted: the call fails, and the same frame sent again is refined
  // (the sums were not consumed).
  ASSERT_NE(Models(), nullptr);
  const Sequence sequence = GenerateSequence(SequenceKind::kStatic, 2, 4);
  Tracker tracker(TrackerOptions{}, &*Models()->inc);
  for (int t = 0; t < 3; ++t) {
    ASSERT_TRUE(
        tracker.Process(sequence.frames[t].frame.frame, std::nullopt).ok());
  }
  const absl::StatusOr<TrackedFrame> stopped =
      tracker.Process(sequence.frames[3].frame.frame, std::nullopt,
                      [] { return absl::CancelledError("stop"); });
  EXPECT_EQ(stopped.status().code(), absl::StatusCode::kCancelled);
  EXPECT_EQ(tracker.segmentations(), 1);
  const absl::StatusOr<TrackedFrame> again =
      tracker.Process(sequence.frames[3].frame.frame, std::nullopt);
  ASSERT_TRUE(again.ok()) << again.status();
  EXPECT_TRUE(again->refined);
  EXPECT_EQ(tracker.segmentations(), 2);
}

TEST(Tracker, AnObjectTakenAwayIsGoneOnceAndTheOthersKeepTheirIdentities) {
  ASSERT_NE(Models(), nullptr);
  const Sequence sequence = GenerateSequence(SequenceKind::kRemove, 5, 8);
  std::vector<TrackedFrame> frames;
  Play(sequence, false, &frames);
  int gone = 0;
  std::set<int> gone_ids;
  for (const TrackedFrame& f : frames) {
    for (const TrackedObject& o : f.objects) {
      if (o.state != TrackState::kGone) continue;
      ++gone;
      EXPECT_TRUE(gone_ids.insert(o.track_id).second)
          << "track " << o.track_id << " reported gone twice";
      EXPECT_TRUE(o.object.mask.empty());
    }
  }
  const int taken_away =
      static_cast<int>(sequence.frames.front().object_ids.size() -
                       sequence.frames.back().object_ids.size());
  ASSERT_GT(taken_away, 0);
  EXPECT_GE(gone, taken_away);
  // The one object that stays keeps one identity all along.
  const int stays = sequence.frames.back().object_ids.front();
  std::set<int> ids_of_stays;
  for (size_t t = 0; t < frames.size(); ++t) {
    for (const TrackedObject& o : frames[t].objects) {
      if (o.state != TrackState::kGone &&
          TruthOf(sequence.frames[t], o.object.mask) == stays) {
        ids_of_stays.insert(o.track_id);
      }
    }
  }
  EXPECT_EQ(ids_of_stays.size(), 1u);
}

TEST(Tracker, ADriftingCameraKeepsEveryIdentityWithAndWithoutItsPose) {
  ASSERT_NE(Models(), nullptr);
  const Sequence sequence = GenerateSequence(SequenceKind::kDrift, 7, 6);
  for (const bool with_pose : {true, false}) {
    std::vector<TrackedFrame> frames;
    const std::map<int, std::set<int>> tracks =
        Play(sequence, with_pose, &frames);
    EXPECT_FALSE(tracks.empty());
    for (const auto& [truth, ids] : tracks) {
      EXPECT_EQ(ids.size(), 1u)
          << "object " << truth << (with_pose ? " with" : " without")
          << " the pose";
    }
    for (size_t t = 1; t < frames.size(); ++t) {
      EXPECT_FALSE(frames[t].reused);  // the camera moved
    }
  }
}

TEST(Tracker, AMovingCameraDoesNotNumberAPieceOfAnUnchangedObjectAnew) {
  ASSERT_NE(Models(), nullptr);
  // Drift seed 25, the pose sent: now and then INC cut a still object in
  // two, and the piece that did not keep the track appeared under a new
  // identity (8 masks under identities of no object of their own). Seen
  // from the last frame's view by the poses, its pixels did not change: it
  // joins the part that kept the track. Every identity reported is then one
  // object's: as many identities as objects.
  const Sequence sequence = GenerateSequence(SequenceKind::kDrift, 25, 12);
  std::vector<TrackedFrame> frames;
  const std::map<int, std::set<int>> tracks = Play(sequence, true, &frames);
  std::set<int> reported;
  for (const TrackedFrame& f : frames) {
    for (const TrackedObject& o : f.objects) reported.insert(o.track_id);
  }
  EXPECT_EQ(reported.size(), tracks.size());
}

TEST(Tracker, AnObjectPutDownElsewhereKeepsItsIdentityByItsColour) {
  ASSERT_NE(Models(), nullptr);
  // 9 frames: the object is lifted out of view at frame 3 and put down
  // 12 cm away, outside the association's gate, at frame 6. (Seed 4 was
  // used until INC's gap neighbours: its object put down is then 1.66x the
  // size it was last seen at, past reidentify_size; of seeds 1-8, 2, 3 and
  // 5-8 pass.)
  const Sequence sequence = GenerateSequence(SequenceKind::kPickAndPlace, 2, 9);
  std::set<int> lifted;
  for (int id : sequence.frames[0].object_ids) lifted.insert(id);
  for (int id : sequence.frames[4].object_ids) lifted.erase(id);
  ASSERT_EQ(lifted.size(), 1u);
  const int moving = *lifted.begin();
  std::vector<TrackedFrame> frames;
  std::map<int, std::set<int>> tracks = Play(sequence, true, &frames);
  EXPECT_EQ(tracks[moving].size(), 1u);
  bool came_back_moved = false;
  for (const TrackedObject& o : frames[6].objects) {
    if (o.state != TrackState::kGone &&
        TruthOf(sequence.frames[6], o.object.mask) == moving) {
      came_back_moved |= o.state == TrackState::kMoved;
    }
  }
  EXPECT_TRUE(came_back_moved);
  // Without re-identification it comes back as a new identity.
  TrackerOptions blind;
  blind.reidentify_distance = 0.0f;
  tracks = Play(sequence, true, nullptr, blind);
  EXPECT_EQ(tracks[moving].size(), 2u);
}

TEST(Tracker, TheSupportIsKeptWhileItFits) {
  ASSERT_NE(Models(), nullptr);
  const Sequence sequence = GenerateSequence(SequenceKind::kDrift, 7, 4);
  // With the pose: the plane found in frame 0 is moved into each camera.
  std::vector<TrackedFrame> frames;
  Play(sequence, true, &frames);
  ASSERT_EQ(frames.size(), 4u);
  EXPECT_FALSE(frames[0].support_kept);
  for (size_t t = 1; t < frames.size(); ++t) {
    EXPECT_TRUE(frames[t].support_kept) << "frame " << t;
    EXPECT_FALSE(frames[t].objects.empty());
  }
  // Without it, a camera that moved changes most pixels: searched afresh.
  frames.clear();
  Play(sequence, false, &frames);
  for (const TrackedFrame& f : frames) EXPECT_FALSE(f.support_kept);
  // A pose that jumps at frame 2 (the camera said 30 cm higher than it
  // is): the plane it gives holds nothing there, so frame 2 is segmented
  // with a search; frame 3's true pose then disagrees with the plane frame
  // 2 left, and it is searched for again.
  Sequence jumping = sequence;
  jumping.frames[2].camera_to_world.pretranslate(Eigen::Vector3f(0, 0, 0.3f));
  frames.clear();
  Play(jumping, true, &frames);
  ASSERT_EQ(frames.size(), 4u);
  EXPECT_TRUE(frames[1].support_kept);
  EXPECT_FALSE(frames[2].support_kept);
  EXPECT_FALSE(frames[3].support_kept);
  for (const TrackedFrame& f : frames) EXPECT_FALSE(f.objects.empty());
}

// The ground-truth objects of `frame` with their pixel centroids.

// The identity of the object of `sequence` whose pixels' centroid moved
// most from the first frame to the last: the one pushed.
int PushedObject(const Sequence& sequence) {
  const auto centroids = [](const synth::SequenceFrame& f) {
    std::map<int, cv::Point2d> at;
    for (size_t k = 0; k < f.object_ids.size(); ++k) {
      const cv::Moments m = cv::moments(PixelsOfObject(f, k), true);
      if (m.m00 > 0) at[f.object_ids[k]] = {m.m10 / m.m00, m.m01 / m.m00};
    }
    return at;
  };
  const std::map<int, cv::Point2d> first = centroids(sequence.frames.front());
  const std::map<int, cv::Point2d> last = centroids(sequence.frames.back());
  int pushed = -1;
  double most = 0.0;
  for (const auto& [id, at] : first) {
    if (last.count(id) == 0) continue;
    const double moved = cv::norm(last.at(id) - at);
    if (moved > most) {
      most = moved;
      pushed = id;
    }
  }
  return pushed;
}

TEST(Tracker, APushedObjectIsCutAgainInItsRegionAndTheRestIsKeptAsItWas) {
  ASSERT_NE(Models(), nullptr);
  const Sequence sequence = GenerateSequence(SequenceKind::kPush, 3, 8);
  const int pushed = PushedObject(sequence);
  ASSERT_GE(pushed, 0);
  std::vector<TrackedFrame> frames;
  const std::map<int, std::set<int>> tracks = Play(sequence, false, &frames);
  int regions = 0;
  for (size_t t = 1; t < frames.size(); ++t) {
    const cv::Rect region = frames[t].region;
    if (region.empty()) continue;
    ++regions;
    EXPECT_LT(region.area(), frames[t].objects.front().object.mask.total() / 2);
    int masks_of_pushed = 0;
    for (const TrackedObject& o : frames[t].objects) {
      if (o.state == TrackState::kGone) continue;
      masks_of_pushed += TruthOf(sequence.frames[t], o.object.mask) == pushed;
      if (!(o.object.box & region).empty()) continue;
      // Outside the region: the last frame's object, pixel for pixel.
      EXPECT_EQ(o.state, TrackState::kKept);
      const auto before = std::find_if(
          frames[t - 1].objects.begin(), frames[t - 1].objects.end(),
          [&](const TrackedObject& b) { return b.track_id == o.track_id; });
      ASSERT_NE(before, frames[t - 1].objects.end()) << "track " << o.track_id;
      EXPECT_EQ(cv::countNonZero(before->object.mask != o.object.mask), 0)
          << "track " << o.track_id << ", frame " << t;
    }
    // The pushed object comes back as one mask.
    EXPECT_EQ(masks_of_pushed, 1) << "frame " << t;
  }
  // Of the 7 frames after the first, where it moved, all but every third
  // (TrackerOptions::region_whole_every, 2): 5, and 4 should one of them
  // have been cut whole for cause.
  EXPECT_GE(regions, 4);
  // With one identity all along.
  ASSERT_EQ(tracks.count(pushed), 1u);
  EXPECT_EQ(tracks.at(pushed).size(), 1u);
}

TEST(Tracker, BadOptionsAreNamed) {
  TrackerOptions options;
  options.static_fraction = 1.5;
  EXPECT_EQ(Validate(options).code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(Validate(options).message().find("track.static_fraction"),
            std::string::npos);
  options = TrackerOptions{};
  options.match_area_ratio = 0.5f;
  EXPECT_NE(Validate(options).message().find("track.match_area_ratio"),
            std::string::npos);
  options = TrackerOptions{};
  options.region.max_fraction = 0.0;
  EXPECT_NE(Validate(options).message().find("track.region.max_fraction"),
            std::string::npos);
  options = TrackerOptions{};
  options.match_m = 0.0f;
  EXPECT_NE(Validate(options).message().find("track.match_m"),
            std::string::npos);
  Tracker tracker(options, nullptr);
  RgbdFrame frame;
  EXPECT_EQ(tracker.Process(frame, std::nullopt).status().code(),
            absl::StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace fovea::tracker_testing
