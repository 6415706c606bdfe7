#ifndef FOVEA_CORE_TRACK_TRACKER_H_
#define FOVEA_CORE_TRACK_TRACKER_H_

#include <Eigen/Geometry>
#include <algorithm>
#include <optional>
#include <vector>

#include "absl/status/statusor.h"
#include "core/base/interrupt.h"
#include "core/base/stage_clock.h"
#include "core/frame/rgbd_frame.h"
#include "core/frame/sensor_model.h"
#include "core/pipeline/incremental.h"
#include "core/pipeline/segment.h"
#include "core/segmentation/rbf_svm.h"
#include "core/track/object_ops.h"
#include "core/track/region.h"

namespace fovea {

// A camera that keeps looking: the frames of one stream, segmented with
// INC (incremental.h) and their objects given identities that persist
// while they stay in view.
//
// What time is used for:
//   - A frame in which neither depth nor colour changed beyond the
//     sensor's noise since the frame last segmented (and whose camera pose,
//     when given, did not move) is not segmented again: its objects are the
//     last ones, kept. This is the cheap case, a static scene.
//   - Objects are associated from frame to frame in 3D: their centroids in
//     the world when the camera pose is given, else in the camera frame
//     (the support and the objects anchor a camera that moves a little
//     between frames), by the one-to-one assignment of least distance
//     within a gate.
//   - The support is kept while it fits (TrackerOptions::reuse_support).
//   - Only what changed is segmented again: with a still camera, a frame
//     in which a part changed (an object placed, pushed or taken away) is
//     segmented in the region around the change (region.h), on the kept
//     support; the objects of the last frame outside it are kept as they
//     were (TrackerOptions::reuse_regions).
//   - What changed comes first: with a still camera, the pixels that
//     changed are INC's temporal cue (IncrementalOptions::change), so that
//     its attention goes to them first; objects that appeared or moved are
//     reported before those kept.
//   - An object that comes back elsewhere (picked up and put down) keeps
//     its identity when its colour and size are those of a track that
//     matched nothing (TrackerOptions::reidentify_distance).
//   - Pieces that move rigidly together become one object: two tracks whose
//     masks touch, with no depth edge along most of the border between
//     them, and that moved by the same displacement (more than moved_m,
//     within joint_motion_m of each other) join; the larger
//     one's identity stays (the older's at equal size). A joined object keeps
//     its pieces: when INC cuts it again, a part that moved more than
//     joint_motion_m apart from the rest (the two were separate objects swept
//     along together) splits off under the identity its piece had before
//     the join, whether it no longer touches the rest or touches it still
//     outside the joined mask (pushed along together, the cut between the
//     two moved), unless another part took that piece. The pieces are
//     carried along while INC cuts the object whole, and so is a piece with
//     an identity of its own that no part of the frame is (hidden, or cut
//     into the rest), until its part comes back; when the joined track
//     matches no object (its parts moved apart, its centroid between them),
//     each part that is one of its pieces takes that piece's identity.

enum class TrackState {
  kAppeared,  // first seen in this frame: a new track_id
  kKept,      // seen before, still where it was
  kMoved,     // seen before, its centroid moved more than moved_m
  kGone,      // seen before, not in this frame (reported once, no mask)
};

// "appeared", "kept", "moved", "gone".
std::string_view TrackStateName(TrackState state);

struct TrackerOptions {
  IncrementalOptions segment;  // each fresh segmentation
  // A pixel changed when its depth moved more than
  // max(change_min_m, change_sigmas * the sensor's sigma(z)), came or went,
  // or a colour channel moved more than color_change (8-bit units); what
  // survives a 5 x 5 opening of those pixels is the change (noise changes
  // single pixels). A frame is unchanged when the change is at most
  // static_fraction of the pixels with depth in either frame (0.0005: 150
  // pixels of a 640 x 480 frame, a 3 cm object at 1 m).
  float change_sigmas = 5.0f;
  float change_min_m = 0.004f;
  float color_change = 40.0f;
  double static_fraction = 0.0005;
  // With poses: a camera that moved less than this is still.
  float still_m = 0.003f;
  float still_rad = 0.005f;
  // Association gate: centroids further apart than
  // max(match_m, match_extent_fraction * the object's largest extent) are
  // not the same object.
  float match_m = 0.06f;
  float match_extent_fraction = 0.5f;
  // Nor are a track and an object whose areas (pixels) differ by more than
  // this factor: a small fragment beside a whole object that moved is not
  // that object (the pieces' rules below give the whole its identity).
  float match_area_ratio = 4.0f;
  float moved_m = 0.02f;
  float joint_motion_m = 0.01f;
  // Two objects that moved together join only when most of the border
  // between them (across a gap of up to 3 pixels) is not a jump in depth
  // beyond the sensor's noise (DepthChanged): two objects one stands in
  // front of are not pieces of one. True joins them all the same (as
  // before the twenty-first session). On 30 push-apart sequences: IDF1
  // 0.862 -> 0.897, joins 44 -> 27; drift, approach and push unchanged.
  bool join_across_depth_edges = false;
  // The support while it fits: the plane of the last frame segmented is
  // given to the next (SupportHints::plane: no search), moved by the
  // camera's pose when given, else only when at most reuse_support_changed
  // of the pixels changed (the camera did not move). When it then holds
  // fewer than support_fit of the inliers it had when last searched for,
  // the frame is segmented again with a search. Not when the options give a
  // plane.
  bool reuse_support = true;
  double reuse_support_changed = 0.1;
  double support_fit = 0.8;
  // Unchanged regions kept: when the camera is still, the support kept
  // (reuse_support) and at most reuse_support_changed of the pixels
  // changed, only RegionToSegment of the changed pixels (and of any two
  // objects of the last frame that touch: they may be pieces of one) is
  // segmented: its part of the frame cut out, INC on it, the objects put
  // back at the frame's pixels. The objects seen in the last frame that lie
  // outside it are kept as they were (no more than max_objects in all, what
  // changed first). The whole frame is segmented instead, with what is left
  // of the time budget, when the region is larger than region.max_fraction
  // of it, when an object found in it reaches its border inside the frame
  // (it may go on outside), when an object of the last frame in it whose
  // pixels did not change is not found again, when the options give
  // attention points (pixels of the whole frame) or ask for point indices,
  // and when the frame's mean is refined.
  bool reuse_regions = true;
  RegionOptions region;
  // After this many region-only segmentations in a row, the next changed
  // frame is segmented whole: what a region never takes in (an object
  // missed, or cut in pieces, by the last whole cut) gets another look, as
  // it would with every changed frame segmented whole. 2: every third
  // (on 30 synthetic sequences of each kind, 2 kept push-apart's IDF1 at
  // that of whole frames, 3 and 4 lost 0.004 and 0.006 of it).
  int region_whole_every = 2;
  // A still scene is looked at again: once refine_frames frames in a row
  // are unchanged (the one last segmented among them), their mean is
  // segmented, once per still period: each pixel's depth averaged over the
  // frames with depth there (in at least half of them, else none), with the
  // colour of the frame last segmented. The sensor's depth noise that
  // differs frame to frame falls by sqrt(n), and the tracks are associated
  // as with any frame. The mean is kept in place of the frame last
  // segmented (which the change test compares with), plus a count per
  // pixel. 0: never; else 2 to 64.
  int refine_frames = 6;
  // The stream's first still period (and the first after a new camera) is
  // refined after this many frames instead: everything in view then comes
  // from one frame's cut, while later periods keep the refined objects of
  // what did not change. Only the first: a period that ends before its
  // refined cut paid for its votes (refine_votes applies as to
  // refine_frames), and in a scene changed every few frames most would.
  // 0: as refine_frames; else 2 to 64.
  int refine_first_frames = 4;
  // The refined cut is voted on: the last refine_votes frames of the still
  // period before it are cut too, unseen (each is answered as reused), and
  // two objects of the refined cut join when most of those cuts and the
  // period's first hold them as one (an object covering more than half of
  // each), unless most of the border between them is a jump in depth beyond
  // the sensor's noise (DepthChanged, on the mean). The cut of the mean is the
  // better cut where the noise that differs frame to frame misleads INC; single
  // frames' cuts err apart where INC is unsure whatever the noise (an object in
  // two pieces in one frame, whole in the next), and most of them hold it whole
  // when the mean's does not. Only joins: an object the single frames miss, or
  // cut in pieces alike, is as the mean's cut has it. The last frames, so that
  // a period that ends before its refined cut seldom paid for votes. 0: the
  // cut of the mean alone; at most refine_frames - 2 are cut, whatever this
  // asks.
  int refine_votes = 2;
  // A gone track may come back (same identity) within this many frames.
  int remember_frames = 30;
  // Re-identification: an object that matched no track (outside the gate:
  // picked up and put down elsewhere, pushed fast) takes the identity of a
  // track that matched nothing when their colours are alike (Bhattacharyya
  // distance of 4 x 4 x 4 RGB histograms at most reidentify_distance),
  // their largest extents within a factor reidentify_size, and it lies
  // within reidentify_m of where the track was last seen. 0 turns it off.
  float reidentify_distance = 0.3f;
  float reidentify_size = 1.5f;
  float reidentify_m = 0.5f;
};

absl::Status Validate(const TrackerOptions& options);

struct TrackedObject {
  int track_id = 0;  // 1, 2, ...: unique in the stream
  TrackState state = TrackState::kAppeared;
  // The object in this frame (mask at the frame's size, box, centroid,
  // geometry, ...); empty mask for kGone.
  SegmentedObject object;
  // Its centroid in the world (camera frame when no pose is given).
  Eigen::Vector3f world_centroid = Eigen::Vector3f::Zero();
  int frames_seen = 0;  // frames it was in, this one included
};

struct TrackedFrame {
  int frame_index = 0;  // 0, 1, ... of the stream
  // Appeared and moved first, then kept, then gone.
  std::vector<TrackedObject> objects;
  // The scene did not change: the last segmentation was reused.
  bool reused = false;
  // The scene did not change for TrackerOptions::refine_frames frames, and
  // their mean was segmented (and voted on: TrackerOptions::refine_votes).
  bool refined = false;
  // The scene did not change and the last segmentation was reused, but
  // this frame was cut too, for the refined cut's vote.
  bool voted = false;
  // See TrackerOptions::static_fraction; 1 when the pose says the camera
  // moved (the pixels are then not compared).
  double changed_fraction = 0.0;
  int joined = 0;  // tracks joined into others in this frame
  // Parts of joined tracks that moved apart in this frame: each is an
  // object of its own again.
  int split = 0;
  // Segmented on the last frame's support plane (no search).
  bool support_kept = false;
  // Only this part of the frame was segmented, the objects outside it kept
  // (TrackerOptions::reuse_regions); empty: the whole frame (or none).
  cv::Rect region;
  // "change", INC's stages, "associate"; "vote" on a frame voted.
  std::vector<StageTiming> timings;
  double seconds = 0.0;
};

class Tracker {
 public:
  // `models` (not owned) hold INC's model of each sensor family; each frame
  // is segmented with its family's (SegmentModels::IncFor). They outlive
  // the tracker.
  Tracker(const TrackerOptions& options, const SegmentModels& models);
  // One INC model (not owned) for frames of every sensor.
  Tracker(const TrackerOptions& options, const RbfSvm* relation_svm);

  // One frame of the stream: segments it (or reuses the last segmentation)
  // and associates its objects with the tracks. `camera_to_world`, when
  // given, is the camera's pose. A frame of another size than the last one
  // starts afresh (every track gone). Errors: Validate's (options);
  // RunSegmentIncremental's; `interrupt`'s. After an error the tracker
  // is as before the call.
  absl::StatusOr<TrackedFrame> Process(
      const RgbdFrame& frame,
      const std::optional<Eigen::Isometry3f>& camera_to_world,
      const InterruptCheck& interrupt = {});

  int frames() const { return frame_index_; }
  int segmentations() const { return segmentations_; }

 private:
  struct Track {
    int id = 0;
    // As last seen, its mask cropped to its box (CropMaskToBox).
    SegmentedObject object;
    cv::Mat appearance;  // Appearance() as last seen; empty: no colour
    Eigen::Vector3f world_centroid = Eigen::Vector3f::Zero();
    int frames_seen = 0;
    int last_seen_frame = 0;
    bool composite = false;     // pieces were joined into it
    std::vector<Piece> pieces;  // when composite: its pieces as last seen
  };

  // Re-identification (TrackerOptions::reidentify_distance): gives the
  // objects of `found` that `match` left without a track the candidate
  // tracks it left without an object, whose colour in `color` and size are
  // alike, one-to-one; `world` and `shift` as the association's.
  void Reidentify(const cv::Mat& color,
                  const std::vector<SegmentedObject>& found,
                  const std::vector<Eigen::Vector3f>& world,
                  const Eigen::Vector3f& shift,
                  const std::vector<Track>& tracks,
                  const std::vector<int>& candidates,
                  std::vector<int>& match) const;
  // One frame's objects after the association (Process), for the rules on
  // pieces.
  struct Association {
    std::vector<SegmentedObject> found;
    std::vector<Eigen::Vector3f> world;  // their centroids in the world
    // Without a pose: the camera's own motion, taken from the centroids.
    Eigen::Vector3f shift = Eigen::Vector3f::Zero();
    std::vector<int> track_of;  // per object: its track's index, or -1
    std::vector<Eigen::Vector3f> displacement;  // since its track's last
    std::vector<TrackState> state;
    // Filled by JoinAndSplit, per object: joined into another; pieces
    // joined into it; its pieces (itself first); split off a joined track:
    // the piece it was.
    std::vector<bool> absorbed;
    std::vector<bool> composite;
    std::vector<std::vector<Piece>> pieces;
    std::vector<std::optional<Piece>> split_from;
    // The pixels that changed since the last frame segmented: with a still
    // camera, all; with one moved by a known pose, those of the objects
    // without a track (ChangedSeenFrom); empty when not known.
    cv::Mat changed;
    bool still = false;  // the camera did not move (CameraStill)
    cv::Mat depth;       // the frame segmented (CV_32FC1)
  };
  // The rules on pieces (pieces.cc): objects that moved together and touch
  // join; an object without a track that is one of a joined track's pieces
  // joins it again, unless the two moved apart (split, also while they
  // touch outside its last mask); a track last seen
  // in the previous frame that matched nothing and lies mostly under one
  // object joins it, and so does one that was, with the object's track,
  // the two pieces of a moving object cut in two in the previous frame.
  // Counts in out.joined and out.split.
  void JoinAndSplit(const std::optional<Eigen::Isometry3f>& camera_to_world,
                    Association& a, std::vector<Track>& tracks,
                    TrackedFrame& out) const;
  // The report of `track` leaving view.
  static TrackedObject Gone(const Track& track);
  // kMoved when `motion` is longer than moved_m, else kKept.
  TrackState StateOfMotion(const Eigen::Vector3f& motion) const {
    return motion.norm() > options_.moved_m ? TrackState::kMoved
                                            : TrackState::kKept;
  }
  // The fraction of pixels that changed from the reference frame;
  // `changed` gets them (CV_8UC1, 255 where changed).
  double ChangedFraction(const RgbdFrame& frame, cv::Mat& changed) const;
  // Whether depth `z` moved from `z0` (both > 0) by more than
  // max(change_min_m, change_sigmas sigma(z0)).
  bool DepthChanged(float z, float z0) const;
  // Whether two objects (masks at the frame's size) are two that one stands
  // in front of: along more than half of the border between them (pixel
  // pairs up to `reach` apart: CountBorderJumps) `depth` jumps
  // (DepthChanged). Guards the vote's joins and those of pieces that moved
  // together.
  bool DepthEdgeBetween(const SegmentedObject& a, const SegmentedObject& b,
                        const cv::Mat& depth, int reach) const;
  // With a camera that moved by a known pose (`pose`, the last frame
  // segmented's known): the pixels of `frame` within `area` whose point,
  // moved into the last frame's view, falls where that frame saw no depth or
  // a different one (CV_8UC1 of the frame's size, zero outside `area`).
  cv::Mat ChangedSeenFrom(const RgbdFrame& frame, const Eigen::Isometry3f& pose,
                          const cv::Rect& area) const;
  bool CameraStill(const std::optional<Eigen::Isometry3f>& pose) const;
  // The association's gate for an object of largest extent `extent`:
  // max(match_m, match_extent_fraction * extent), metres.
  float AssociationGate(float extent) const {
    return std::max(options_.match_m, options_.match_extent_fraction * extent);
  }
  // Segments `frame` with INC (`segment` its options) on the last support
  // when TrackerOptions::reuse_support allows; the objects go to `found`,
  // the support to support_. Whether the support was kept.
  absl::StatusOr<bool> Segment(const RgbdFrame& frame,
                               IncrementalOptions segment,
                               const std::optional<Eigen::Isometry3f>& pose,
                               double changed_fraction,
                               std::vector<SegmentedObject>& found,
                               const InterruptCheck& interrupt);

  // Only `region` of `frame` segmented (TrackerOptions::reuse_regions), on
  // the last support, its objects put at the frame's pixels in `found`,
  // followed by the objects of `tracks` seen in the last frame that lie
  // outside it, as they were. False, `found` left empty, when the whole
  // frame must be segmented instead: an object found reaches the region's
  // border inside the frame, the region shows no support, or an object of
  // the last frame in it whose pixels did not change (`changed`, 255 where
  // they did) is not found again.
  absl::StatusOr<bool> SegmentRegion(
      const RgbdFrame& frame, IncrementalOptions segment,
      const std::optional<Eigen::Isometry3f>& pose, const cv::Rect& region,
      const cv::Mat& changed, const std::vector<Track>& tracks,
      std::vector<SegmentedObject>& found, const InterruptCheck& interrupt);
  // The refined cut's vote (TrackerOptions::refine_votes): objects of
  // `found` (the cut of the mean, masks at the frame's size) that most of
  // the still period's first cut (the objects of `tracks` seen last frame)
  // and votes_ hold as one (HeldAsOne) are joined, each group into its
  // largest, unless `depth` (the mean's) jumps along most of the border
  // between them. votes_ are used up.
  void JoinAsVoted(const std::vector<Track>& tracks, const cv::Mat& depth,
                   std::vector<SegmentedObject>& found);
  // The support plane (support_) in the camera at `pose`.
  Eigen::Vector4f SupportInCamera(
      const std::optional<Eigen::Isometry3f>& pose) const;

  TrackerOptions options_;
  absl::Status valid_;  // Validate(options_), once
  SegmentModels models_;
  const RbfSvm* relation_svm_;  // models_' for the frame being processed
  SensorModel sensor_;
  // The frame last segmented and its pose.
  RgbdFrame reference_;
  std::optional<Eigen::Isometry3f> reference_pose_;
  std::vector<Track> tracks_;  // in view at the last frame, or remembered
  // The support plane of the last frame segmented, in the world (camera
  // frame without a pose), and its inliers when it was last searched for.
  std::optional<Eigen::Vector4f> support_;
  int support_inliers_ = 0;
  int next_id_ = 1;
  int frame_index_ = 0;
  int segmentations_ = 0;
  // Region-only segmentations since the last whole one
  // (TrackerOptions::region_whole_every).
  int regions_in_a_row_ = 0;
  // TrackerOptions::refine_frames: the unchanged frames whose depth is
  // averaged into reference_.depth since the last segmentation (0: none
  // yet), how many of them had depth at each pixel (CV_8UC1; empty while
  // none), and whether this still period was refined.
  int still_frames_ = 0;
  cv::Mat still_count_;
  bool refined_ = false;
  // Segmentations since the stream began or the camera changed: 1 during
  // the first still period (TrackerOptions::refine_first_frames).
  int cuts_in_view_ = 0;
  // TrackerOptions::refine_votes: the still period's frames cut so far for
  // the vote (their objects held, CropMaskToBox).
  std::vector<std::vector<SegmentedObject>> votes_;
  // Averages `depth` into `mean` (CV_32FC1) where it has depth; `count`
  // (CV_8UC1) counts the frames averaged at each pixel. `depth` may be
  // `mean` itself (with `count` 0: counts its pixels with depth).
  static void AverageInto(const cv::Mat& depth, cv::Mat& mean, cv::Mat& count);
  // The still period's length before its refined cut: refine_frames, or
  // refine_first_frames in the first still period (cuts_in_view_ 1).
  int RefineFrames() const;
};

}  // namespace fovea

#endif  // FOVEA_CORE_TRACK_TRACKER_H_
