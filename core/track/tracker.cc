#include "core/track/tracker.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <utility>

#include "absl/strings/str_cat.h"
#include "core/base/status_macros.h"
#include "core/eval/hungarian.h"
#include "core/frame/sensor_model.h"
#include "core/track/object_ops.h"

namespace fovea {
namespace {

float LargestExtent(const SegmentedObject& object) {
  return object.extent.maxCoeff();
}

int StateOrder(TrackState state) {
  switch (state) {
    case TrackState::kAppeared:
      return 0;
    case TrackState::kMoved:
      return 1;
    case TrackState::kKept:
      return 2;
    case TrackState::kGone:
      return 3;
  }
  return 4;
}

}  // namespace

std::string_view TrackStateName(TrackState state) {
  switch (state) {
    case TrackState::kAppeared:
      return "appeared";
    case TrackState::kKept:
      return "kept";
    case TrackState::kMoved:
      return "moved";
    case TrackState::kGone:
      return "gone";
  }
  return "unknown";
}

absl::Status Validate(const TrackerOptions& options) {
  FOVEA_RETURN_IF_ERROR(Validate(options.segment));
  const auto positive = [](std::string_view name, double value) {
    if (std::isfinite(value) && value > 0.0) return absl::OkStatus();
    return absl::InvalidArgumentError(
        absl::StrCat("track.", AbslView(name), ": ", value, " is not > 0"));
  };
  FOVEA_RETURN_IF_ERROR(positive("change_sigmas", options.change_sigmas));
  FOVEA_RETURN_IF_ERROR(positive("change_min_m", options.change_min_m));
  FOVEA_RETURN_IF_ERROR(positive("color_change", options.color_change));
  FOVEA_RETURN_IF_ERROR(positive("still_m", options.still_m));
  FOVEA_RETURN_IF_ERROR(positive("still_rad", options.still_rad));
  FOVEA_RETURN_IF_ERROR(positive("match_m", options.match_m));
  FOVEA_RETURN_IF_ERROR(positive("moved_m", options.moved_m));
  FOVEA_RETURN_IF_ERROR(positive("joint_motion_m", options.joint_motion_m));
  if (!(options.static_fraction >= 0.0 && options.static_fraction < 1.0)) {
    return absl::InvalidArgumentError(
        absl::StrCat("track.static_fraction: ", options.static_fraction,
                     " is not in [0, 1)"));
  }
  if (!(options.match_area_ratio >= 1.0f)) {
    return absl::InvalidArgumentError("track.match_area_ratio: must be >= 1");
  }
  if (!(options.match_extent_fraction >= 0.0f)) {
    return absl::InvalidArgumentError(
        "track.match_extent_fraction: must be >= 0");
  }
  if (!(options.reidentify_distance >= 0.0f &&
        options.reidentify_distance <= 1.0f)) {
    return absl::InvalidArgumentError(
        "track.reidentify_distance: must be in [0, 1]");
  }
  FOVEA_RETURN_IF_ERROR(positive("reidentify_size", options.reidentify_size));
  FOVEA_RETURN_IF_ERROR(positive("reidentify_m", options.reidentify_m));
  if (options.remember_frames < 0) {
    return absl::InvalidArgumentError("track.remember_frames: must be >= 0");
  }
  if (options.region.margin_px < 0) {
    return absl::InvalidArgumentError("track.region.margin_px: must be >= 0");
  }
  if (options.region.min_size.width <= 0 ||
      options.region.min_size.height <= 0) {
    return absl::InvalidArgumentError("track.region.min_size: must be > 0");
  }
  if (!(options.region.max_fraction > 0.0 &&
        options.region.max_fraction <= 1.0)) {
    return absl::InvalidArgumentError(
        absl::StrCat("track.region.max_fraction: ", options.region.max_fraction,
                     " is not in (0, 1]"));
  }
  if (options.region_whole_every < 1) {
    return absl::InvalidArgumentError("track.region_whole_every: must be >= 1");
  }
  if (options.refine_votes < 0 || options.refine_votes > 31) {
    return absl::InvalidArgumentError(absl::StrCat(
        "track.refine_votes: ", options.refine_votes, " is not in [0, 31]"));
  }
  if (options.refine_frames < 0 || options.refine_frames == 1 ||
      options.refine_frames > 64) {
    return absl::InvalidArgumentError(
        absl::StrCat("track.refine_frames: ", options.refine_frames,
                     " is not 0 or in [2, 64]"));
  }
  if (options.refine_first_frames < 0 || options.refine_first_frames == 1 ||
      options.refine_first_frames > 64) {
    return absl::InvalidArgumentError(
        absl::StrCat("track.refine_first_frames: ", options.refine_first_frames,
                     " is not 0 or in [2, 64]"));
  }
  return absl::OkStatus();
}

int Tracker::RefineFrames() const {
  if (cuts_in_view_ != 1 || options_.refine_first_frames == 0 ||
      options_.refine_frames == 0) {
    return options_.refine_frames;
  }
  return options_.refine_first_frames;
}

Tracker::Tracker(const TrackerOptions& options, const SegmentModels& models)
    : options_(options),
      valid_(Validate(options)),
      models_(models),
      relation_svm_(models.inc) {}

Tracker::Tracker(const TrackerOptions& options, const RbfSvm* relation_svm)
    : Tracker(options, SegmentModels{.inc = relation_svm}) {}

void Tracker::Reidentify(const cv::Mat& color,
                         const std::vector<SegmentedObject>& found,
                         const std::vector<Eigen::Vector3f>& world,
                         const Eigen::Vector3f& shift,
                         const std::vector<Track>& tracks,
                         const std::vector<int>& candidates,
                         std::vector<int>& match) const {
  std::vector<bool> taken(found.size(), false);
  std::vector<int> free_tracks;
  for (size_t i = 0; i < match.size(); ++i) {
    if (match[i] >= 0) {
      taken[match[i]] = true;
    } else if (!tracks[candidates[i]].appearance.empty()) {
      free_tracks.push_back(static_cast<int>(i));
    }
  }
  std::vector<int> free_objects;
  std::vector<cv::Mat> looks;
  for (size_t j = 0; j < found.size(); ++j) {
    if (taken[j]) continue;
    cv::Mat look = Appearance(color, found[j]);
    if (look.empty()) continue;
    free_objects.push_back(static_cast<int>(j));
    looks.push_back(std::move(look));
  }
  if (free_tracks.empty() || free_objects.empty()) return;
  std::vector<std::vector<double>> score(
      free_tracks.size(), std::vector<double>(free_objects.size(), 0.0));
  for (size_t a = 0; a < free_tracks.size(); ++a) {
    const Track& t = tracks[candidates[free_tracks[a]]];
    for (size_t b = 0; b < free_objects.size(); ++b) {
      const SegmentedObject& o = found[free_objects[b]];
      const float size = std::max(LargestExtent(o), 1e-3f) /
                         std::max(LargestExtent(t.object), 1e-3f);
      if (size > options_.reidentify_size ||
          size * options_.reidentify_size < 1.0f) {
        continue;
      }
      if ((world[free_objects[b]] - shift - t.world_centroid).norm() >
          options_.reidentify_m) {
        continue;
      }
      const double distance =
          cv::compareHist(t.appearance, looks[b], cv::HISTCMP_BHATTACHARYYA);
      if (distance <= options_.reidentify_distance) {
        score[a][b] = 1.0 - distance;
      }
    }
  }
  const std::vector<int> pairs = MaxWeightAssignment(score);
  for (size_t a = 0; a < pairs.size(); ++a) {
    if (pairs[a] >= 0 && score[a][pairs[a]] > 0.0) {
      match[free_tracks[a]] = free_objects[pairs[a]];
    }
  }
}

TrackedObject Tracker::Gone(const Track& track) {
  TrackedObject gone;
  gone.track_id = track.id;
  gone.state = TrackState::kGone;
  gone.world_centroid = track.world_centroid;
  gone.frames_seen = track.frames_seen;
  gone.object.index = -1;  // no mask: only the last centroid
  gone.object.centroid = track.object.centroid;
  return gone;
}

absl::StatusOr<TrackedFrame> Tracker::Process(
    const RgbdFrame& frame,
    const std::optional<Eigen::Isometry3f>& camera_to_world,
    const InterruptCheck& interrupt) {
  FOVEA_RETURN_IF_ERROR(valid_);
  const SteadyClock::time_point start = SteadyClock::now();
  TrackedFrame out;
  out.frame_index = frame_index_;
  StageClock clock(out.timings);
  sensor_ =
      SensorModelFor(options_.segment.detect.scene.sensor, frame.intrinsics);
  relation_svm_ = models_.IncFor(frame, options_.segment.detect.scene);
  std::vector<Track> tracks = tracks_;
  const bool same_size = segmentations_ > 0 && !reference_.depth.empty() &&
                         reference_.depth.size() == frame.depth.size();
  if (!same_size) {
    // A new camera (or the first frame): what was in view is gone.
    for (const Track& t : tracks) {
      if (t.last_seen_frame != frame_index_ - 1) continue;
      out.objects.push_back(Gone(t));
    }
    tracks.clear();
    support_.reset();
    cuts_in_view_ = 0;
  }
  // A camera known to have moved sees every pixel change: not looked at.
  const bool still = same_size && CameraStill(camera_to_world);
  cv::Mat changed;
  out.changed_fraction = still ? ChangedFraction(frame, changed) : 1.0;
  clock.Lap("change");

  bool reuse = still && out.changed_fraction <= options_.static_fraction;
  // The frame segmented: this one, or the mean of a still period's. Until
  // the segmentation succeeds, the mean so far is left as it was (the
  // refining frame averages into a copy).
  RgbdFrame mean;
  const int refine_frames = RefineFrames();
  if (reuse && refine_frames > 0 && !refined_) {
    if (still_frames_ == 0) {
      still_count_ = cv::Mat(reference_.depth.size(), CV_8UC1, cv::Scalar(0));
      AverageInto(reference_.depth, reference_.depth, still_count_);
      still_frames_ = 1;
    }
    if (still_frames_ + 1 < refine_frames) {
      AverageInto(frame.depth, reference_.depth, still_count_);
      ++still_frames_;
      out.voted = refine_frames - still_frames_ <= options_.refine_votes;
    } else {
      mean.intrinsics = frame.intrinsics;
      mean.color = reference_.color;
      mean.depth = reference_.depth.clone();
      cv::Mat count = still_count_.clone();
      AverageInto(frame.depth, mean.depth, count);
      // Depth only where at least half the frames had some.
      mean.depth.setTo(0.0f, count * 2 < still_frames_ + 1);
      reuse = false;
      out.refined = true;
    }
  }
  const RgbdFrame& input = out.refined ? mean : frame;
  if (reuse) {
    out.reused = true;
    for (Track& t : tracks) {
      if (t.last_seen_frame != frame_index_ - 1) continue;
      t.last_seen_frame = frame_index_;
      ++t.frames_seen;
      TrackedObject kept;
      kept.track_id = t.id;
      kept.state = TrackState::kKept;
      kept.object = t.object;
      kept.object.mask = MaskAtSize(t.object, frame.depth.size());
      kept.world_centroid = t.world_centroid;
      kept.frames_seen = t.frames_seen;
      out.objects.push_back(std::move(kept));
    }
    if (out.voted) {
      // A cut that fails is no vote; the frame is answered all the same.
      // Its objects' points are not taken: the vote looks at masks.
      IncrementalOptions vote_options = options_.segment;
      vote_options.object_points = ObjectPointsOptions{};
      std::vector<SegmentedObject> cut;
      if (Segment(frame, std::move(vote_options), camera_to_world,
                  out.changed_fraction, cut, interrupt)
              .ok()) {
        std::vector<SegmentedObject>& vote = votes_.emplace_back();
        for (SegmentedObject& o : cut) {
          CropMaskToBox(o);
          vote.push_back(OutlineOf(o));
        }
      } else {
        out.voted = false;
      }
      clock.Lap("vote");
    }
  } else {
    Association a;
    std::vector<SegmentedObject>& found = a.found;
    // What changed is where attention goes first.
    IncrementalOptions segment = options_.segment;
    if (still && !out.refined && segment.change_weight > 0.0f) {
      segment.change = changed;
    }
    // Only what changed, when the rest can be kept as it was.
    std::optional<cv::Rect> region;
    if (options_.reuse_regions && options_.reuse_support && still &&
        !out.refined && support_ &&
        regions_in_a_row_ < options_.region_whole_every &&
        out.changed_fraction <= options_.reuse_support_changed &&
        segment.attention_points.empty() &&
        segment.object_points.format != ObjectPointsFormat::kIndices) {
      std::vector<const SegmentedObject*> last;
      std::vector<cv::Rect> held;
      for (const Track& t : tracks) {
        if (t.last_seen_frame != frame_index_ - 1) continue;
        last.push_back(&t.object);
        held.push_back(t.object.box);
      }
      // Objects that touch may be pieces of one: cut again with what
      // changed, as the whole frame would cut them again, so that a whole
      // cut can join them.
      cv::Mat around = changed.clone();
      for (size_t i = 0; i < last.size(); ++i) {
        for (size_t k = i + 1; k < last.size(); ++k) {
          if (HeldTouch(*last[i], *last[k], frame.depth.size(), 3)) {
            around(last[i]->box).setTo(255);
            around(last[k]->box).setTo(255);
          }
        }
      }
      region = RegionToSegment(around, held, options_.region);
    }
    bool partial = false;
    if (region) {
      const SteadyClock::time_point region_start = SteadyClock::now();
      FOVEA_ASSIGN_OR_RETURN(
          partial, SegmentRegion(input, segment, camera_to_world, *region,
                                 changed, tracks, found, interrupt));
      // The whole frame's cut, instead, has what is left of the frame's
      // time budget.
      if (!partial && segment.time_budget_seconds > 0.0) {
        segment.time_budget_seconds = std::max(
            1e-3, segment.time_budget_seconds - SecondsSince(region_start));
      }
    }
    if (partial) {
      out.region = *region;
      out.support_kept = true;
      ++regions_in_a_row_;
    } else {
      regions_in_a_row_ = 0;
      FOVEA_ASSIGN_OR_RETURN(out.support_kept,
                             Segment(input, std::move(segment), camera_to_world,
                                     out.changed_fraction, found, interrupt));
    }
    clock.Lap("segment");
    if (out.refined && !votes_.empty()) JoinAsVoted(tracks, input.depth, found);

    // Candidates: tracks seen within remember_frames.
    std::vector<int> candidates;
    for (int i = 0; i < static_cast<int>(tracks.size()); ++i) {
      if (tracks[i].last_seen_frame >=
          frame_index_ - 1 - options_.remember_frames) {
        candidates.push_back(i);
      }
    }
    std::vector<Eigen::Vector3f>& world = a.world;
    world.resize(found.size());
    for (size_t j = 0; j < found.size(); ++j) {
      world[j] = ToWorld(camera_to_world, found[j].centroid);
    }
    // The gate of each (track, object) pair, and the largest.
    std::vector<std::vector<double>> gate(
        candidates.size(), std::vector<double>(found.size(), 0.0));
    double big = 0.0;
    for (size_t i = 0; i < candidates.size(); ++i) {
      const Track& t = tracks[candidates[i]];
      for (size_t j = 0; j < found.size(); ++j) {
        const int smaller = std::min(t.object.area, found[j].area);
        const int larger = std::max(t.object.area, found[j].area);
        if (static_cast<float>(larger) >
            options_.match_area_ratio * static_cast<float>(smaller)) {
          continue;  // a fragment is not the whole it lies beside
        }
        gate[i][j] = AssociationGate(
            std::max(LargestExtent(t.object), LargestExtent(found[j])));
        big = std::max(big, gate[i][j]);
      }
    }
    // Assigns found objects to candidate tracks, distances taken after
    // subtracting `shift` from the new centroids.
    const auto assign = [&](const Eigen::Vector3f& shift) {
      std::vector<std::vector<double>> score(
          candidates.size(), std::vector<double>(found.size(), 0.0));
      for (size_t i = 0; i < candidates.size(); ++i) {
        const Track& t = tracks[candidates[i]];
        for (size_t j = 0; j < found.size(); ++j) {
          const double d = (world[j] - shift - t.world_centroid).norm();
          score[i][j] = d < gate[i][j] ? 2.0 * big - d : 0.0;
        }
      }
      std::vector<int> match = MaxWeightAssignment(score);
      for (size_t i = 0; i < match.size(); ++i) {
        if (match[i] >= 0 && score[i][match[i]] <= 0.0) match[i] = -1;
      }
      return match;
    };
    Eigen::Vector3f& shift = a.shift;
    std::vector<int> match = assign(shift);
    if (!camera_to_world) {
      // The camera's own motion, as the objects' common displacement.
      std::vector<Eigen::Vector3f> moves;
      for (size_t i = 0; i < match.size(); ++i) {
        if (match[i] >= 0) {
          moves.push_back(world[match[i]] -
                          tracks[candidates[i]].world_centroid);
        }
      }
      if (moves.size() >= 2) {
        shift = CoordinateMedian(moves);
        match = assign(shift);
      }
    }

    if (options_.reidentify_distance > 0.0f) {
      Reidentify(input.color, found, world, shift, tracks, candidates, match);
    }

    std::vector<int>& track_of = a.track_of;
    track_of.assign(found.size(), -1);
    std::vector<Eigen::Vector3f>& displacement = a.displacement;
    displacement.assign(found.size(), Eigen::Vector3f::Zero());
    for (size_t i = 0; i < match.size(); ++i) {
      if (match[i] < 0) continue;
      track_of[match[i]] = candidates[i];
      displacement[match[i]] =
          world[match[i]] - shift - tracks[candidates[i]].world_centroid;
    }
    std::vector<TrackState>& state = a.state;
    state.assign(found.size(), TrackState::kAppeared);
    for (size_t j = 0; j < found.size(); ++j) {
      if (track_of[j] < 0) continue;
      state[j] = StateOfMotion(displacement[j]);
    }
    // A refined cut replaces the last one: its parts are not joined by it.
    if (!out.refined) a.changed = changed;
    a.still = still;
    a.depth = input.depth;
    // With a camera that moved by a known pose, what changed is told in the
    // world, and only when some object has no track.
    if (!still && same_size && camera_to_world && reference_pose_) {
      cv::Rect area;  // where the objects without a track are
      for (size_t j = 0; j < found.size(); ++j) {
        if (track_of[j] < 0) area |= found[j].box;
      }
      if (!area.empty()) {
        a.changed = ChangedSeenFrom(input, *camera_to_world, area);
      }
    }
    JoinAndSplit(camera_to_world, a, tracks, out);
    const std::vector<bool>& absorbed = a.absorbed;
    const std::vector<bool>& composite = a.composite;
    std::vector<std::vector<Piece>>& pieces = a.pieces;
    const std::vector<std::optional<Piece>>& split_from = a.split_from;

    std::vector<bool> seen(tracks.size(), false);
    for (size_t j = 0; j < found.size(); ++j) {
      if (absorbed[j]) continue;
      TrackedObject result;
      if (track_of[j] >= 0) {
        Track& t = tracks[track_of[j]];
        seen[track_of[j]] = true;
        // Moved when both the piece first matched and the object as joined
        // moved: joining changes a centroid without the object moving.
        const float joined_move = (world[j] - shift - t.world_centroid).norm();
        result.state =
            state[j] == TrackState::kMoved && joined_move > options_.moved_m
                ? TrackState::kMoved
                : TrackState::kKept;
        // A joined track that INC cut whole this time keeps its pieces,
        // carried along: they tell its parts apart when they move apart.
        if (t.composite && !composite[j] && IsWhole(found[j].area, t.pieces)) {
          CarryPieces(t.object, t.world_centroid, found[j], world[j], t.pieces);
        } else if (t.composite || composite[j]) {
          KeepFormerIds(shift, t.pieces, pieces[j]);
          CarryUnseenPieces(t.pieces, split_from, t.object, t.world_centroid,
                            found[j], world[j], pieces[j]);
          t.pieces = std::move(pieces[j]);
        }
        t.composite = t.composite || composite[j];
        t.object = found[j];
        CropMaskToBox(t.object);
        t.appearance = Appearance(input.color, found[j]);
        t.world_centroid = world[j];
        t.last_seen_frame = frame_index_;
        ++t.frames_seen;
        result.track_id = t.id;
        result.frames_seen = t.frames_seen;
      } else {
        Track t;
        t.frames_seen = 1;
        result.state = TrackState::kAppeared;
        if (split_from[j].has_value() && split_from[j]->former_id != 0 &&
            std::none_of(tracks.begin(), tracks.end(), [&](const Track& o) {
              return o.id == split_from[j]->former_id;
            })) {
          // A part that splits off gets back the identity it had before.
          t.id = split_from[j]->former_id;
          t.frames_seen = split_from[j]->former_frames_seen + 1;
          result.state =
              StateOfMotion(world[j] - shift - split_from[j]->world_centroid);
        }
        if (t.id == 0) t.id = next_id_++;
        t.object = found[j];
        CropMaskToBox(t.object);
        t.appearance = Appearance(input.color, found[j]);
        t.world_centroid = world[j];
        t.last_seen_frame = frame_index_;
        result.track_id = t.id;
        result.frames_seen = t.frames_seen;
        tracks.push_back(t);
        seen.push_back(true);
      }
      result.object = std::move(found[j]);
      result.world_centroid = world[j];
      out.objects.push_back(std::move(result));
    }
    for (size_t i = 0; i < tracks.size(); ++i) {
      const Track& t = tracks[i];
      if (seen[i] || t.id == 0 || t.last_seen_frame != frame_index_ - 1) {
        continue;
      }
      out.objects.push_back(Gone(t));
    }
    // Forget what has been gone too long, and joined tracks.
    tracks.erase(std::remove_if(tracks.begin(), tracks.end(),
                                [&](const Track& t) {
                                  return t.id == 0 ||
                                         t.last_seen_frame <
                                             frame_index_ -
                                                 options_.remember_frames;
                                }),
                 tracks.end());
    reference_.color = input.color.clone();
    reference_.depth = input.depth.clone();
    reference_.intrinsics = frame.intrinsics;
    // A changed scene starts a still period; a refined one has ended its.
    still_frames_ = 0;
    still_count_.release();
    votes_.clear();
    refined_ = out.refined;
    cuts_in_view_ = std::min(cuts_in_view_ + 1, 2);
    reference_pose_ = camera_to_world;
    ++segmentations_;
    clock.Lap("associate");
  }
  std::stable_sort(out.objects.begin(), out.objects.end(),
                   [](const TrackedObject& a, const TrackedObject& b) {
                     return StateOrder(a.state) < StateOrder(b.state);
                   });
  tracks_ = std::move(tracks);
  ++frame_index_;
  out.seconds = SecondsSince(start);
  return out;
}

}  // namespace fovea
