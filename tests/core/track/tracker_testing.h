#ifndef FOVEA_TESTS_CORE_TRACK_TRACKER_TESTING_H_
#define FOVEA_TESTS_CORE_TRACK_TRACKER_TESTING_H_

// What the tracker's tests share (tracker_test.cc, tracker_pieces_test.cc):
// the shipped models, the ground truth of a synthetic sequence's frames,
// and a sequence played through a tracker.

#include <gtest/gtest.h>

#include <map>
#include <opencv2/core.hpp>
#include <optional>
#include <set>
#include <utility>
#include <vector>

#include "core/pipeline/models.h"
#include "core/synth/sequence.h"
#include "core/track/tracker.h"
#include "tests/core/testing/models.h"

namespace fovea::tracker_testing {

using synth::GenerateSequence;
using synth::Sequence;
using synth::SequenceKind;

inline const LoadedModels* Models() { return testing::ShippedModels(); }

// The pixels of the k-th object present in `frame` (its label, as
// RenderScene's: 10 * (k + 2)).
inline cv::Mat PixelsOfObject(const synth::SequenceFrame& frame, size_t k) {
  return frame.frame.labels == 10 * (static_cast<int>(k) + 2);
}

// Per ground-truth identity: its pixels under `mask`.
inline std::map<int, int> PixelsPerTruth(const synth::SequenceFrame& frame,
                                         const cv::Mat& mask) {
  std::map<int, int> votes;
  for (int v = 0; v < mask.rows; ++v) {
    const uint8_t* m = mask.ptr<uint8_t>(v);
    const int* label = frame.frame.labels.ptr<int>(v);
    for (int u = 0; u < mask.cols; ++u) {
      if (m[u] == 0) continue;
      const int k = label[u] / 10 - 2;
      if (label[u] >= 20 && k < static_cast<int>(frame.object_ids.size())) {
        ++votes[frame.object_ids[k]];
      }
    }
  }
  return votes;
}

// The ground-truth identity of at least 80 % of `mask`'s pixels (-1:
// none: the table, or a mask holding two objects, whose identity is
// neither's).
inline int TruthOf(const synth::SequenceFrame& frame, const cv::Mat& mask) {
  int best = -1;
  int most = cv::countNonZero(mask) * 4 / 5;
  for (const auto& [id, count] : PixelsPerTruth(frame, mask)) {
    if (count > most) {
      best = id;
      most = count;
    }
  }
  return best;
}

// For each of `truths`: the track id of an object of `tracked` (not gone)
// whose mask is mostly that truth in `frame` (TruthOf); truths without
// one are left out.
inline std::map<int, int> IdsOfTruths(const synth::SequenceFrame& frame,
                                      const TrackedFrame& tracked,
                                      const std::vector<int>& truths) {
  std::map<int, int> ids;
  for (const TrackedObject& o : tracked.objects) {
    if (o.state == TrackState::kGone) continue;
    const int truth = TruthOf(frame, o.object.mask);
    if (std::find(truths.begin(), truths.end(), truth) != truths.end()) {
      ids[truth] = o.track_id;
    }
  }
  return ids;
}

// Plays `sequence` through a tracker; for each ground-truth object, the
// track ids that carried its largest mask, frame after frame (a piece of an
// object cut in two is not a second identity; a new id on its largest piece
// is).
inline std::map<int, std::set<int>> Play(
    const Sequence& sequence, bool with_pose,
    std::vector<TrackedFrame>* frames = nullptr,
    const TrackerOptions& options = {}) {
  Tracker tracker(options, &*Models()->inc);
  std::map<int, std::set<int>> tracks_of_truth;
  for (const synth::SequenceFrame& f : sequence.frames) {
    std::optional<Eigen::Isometry3f> pose;
    if (with_pose) pose = f.camera_to_world;
    absl::StatusOr<TrackedFrame> out = tracker.Process(f.frame.frame, pose);
    EXPECT_TRUE(out.ok()) << out.status();
    if (!out.ok()) return {};
    std::map<int, std::pair<int, int>> largest;  // truth -> (area, track)
    for (const TrackedObject& o : out->objects) {
      if (o.state == TrackState::kGone) continue;
      const int truth = TruthOf(f, o.object.mask);
      if (truth < 0) continue;
      std::pair<int, int>& best = largest[truth];
      if (o.object.area > best.first) best = {o.object.area, o.track_id};
    }
    for (const auto& [truth, best] : largest) {
      tracks_of_truth[truth].insert(best.second);
    }
    if (frames != nullptr) frames->push_back(*std::move(out));
  }
  return tracks_of_truth;
}

}  // namespace fovea::tracker_testing

#endif  // FOVEA_TESTS_CORE_TRACK_TRACKER_TESTING_H_
