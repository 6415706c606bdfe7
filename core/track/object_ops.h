#ifndef FOVEA_CORE_TRACK_OBJECT_OPS_H_
#define FOVEA_CORE_TRACK_OBJECT_OPS_H_

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <functional>
#include <opencv2/core.hpp>
#include <optional>
#include <vector>

#include "core/pipeline/segment.h"

namespace fovea {

// What the tracker does to one frame's objects (tracker.h): whether two
// touch, joining pieces into one, an object's colour, the common motion
// of many.

// `p` (camera frame) in the world by the camera's pose; `p` without one.
inline Eigen::Vector3f ToWorld(const std::optional<Eigen::Isometry3f>& pose,
                               const Eigen::Vector3f& p) {
  return pose ? Eigen::Vector3f(*pose * p) : p;
}

// The median of each coordinate of `v` (zero when empty).
Eigen::Vector3f CoordinateMedian(std::vector<Eigen::Vector3f> v);

// `r` grown by `by` pixels on every side (not clipped).
inline cv::Rect Grown(const cv::Rect& r, int by) {
  return {r.x - by, r.y - by, r.width + 2 * by, r.height + 2 * by};
}

// Whether masks `a` and `b` (CV_8UC1, same size; `a_box` and `b_box` their
// bounding boxes) touch: `a` grown by `radius` pixels overlaps `b`.
bool Touch(const cv::Mat& a, const cv::Rect& a_box, const cv::Mat& b,
           const cv::Rect& b_box, int radius);

// Adds `piece` to `into`: the union of the masks, the box and area of the
// union, the area-weighted centroid, the larger extent, both point sets;
// the geometry is dropped (the pieces' boxes are not the whole's).
void Join(const SegmentedObject& piece, SegmentedObject& into);

// The colour of `object` in `color` (RGB, CV_8UC3, the mask's size): a
// 4 x 4 x 4 histogram (CV_32F) of its mask's pixels, to compare with
// cv::compareHist; empty without colour or pixels.
cv::Mat Appearance(const cv::Mat& color, const SegmentedObject& object);

// A piece of a joined object as last seen: its mask within its box and its
// centroid in the world, so that each part's motion can be told, and the
// identity it had before it was joined (0: none), so that a part that
// splits off again gets it back.
struct Piece {
  cv::Rect box;
  cv::Mat mask;  // CV_8UC1 of the box's size, non-zero on the piece
  int area = 0;
  Eigen::Vector3f world_centroid = Eigen::Vector3f::Zero();
  int former_id = 0;
  int former_frames_seen = 0;
};

// `object` (its mask at the frame's size) as a piece, `world_centroid` its
// centroid in the world.
Piece PieceOf(const SegmentedObject& object,
              const Eigen::Vector3f& world_centroid);

// Which of `before` `now` is: of those its mask overlaps whose area is
// within a factor of 1.5 of its own (a piece cut otherwise is not it), the one
// whose centroid is nearest to now's minus `shift` (the camera's own motion);
// -1 when none (the object was cut otherwise this time).
int MatchingPiece(const Piece& now, const Eigen::Vector3f& shift,
                  const std::vector<Piece>& before);

// `pieces` moved as their piece `from` moved to `to` (one part of this
// frame): in the world by its motion less `shift` (the camera's own), in
// the image by the motion of its mask's centroid. Parts pushed along
// together move alike, and a small one moves by more than its own size
// from one frame to the next: it overlaps its piece only once the piece is
// moved.
std::vector<Piece> MovedAs(const std::vector<Piece>& pieces, const Piece& from,
                           const Piece& to, const Eigen::Vector3f& shift);

// The pieces keep the identities they had before being joined: each piece
// of `now` without one takes that of its MatchingPiece in `before`.
void KeepFormerIds(const Eigen::Vector3f& shift,
                   const std::vector<Piece>& before, std::vector<Piece>& now);

// An object as a track holds it between frames: its mask cropped to its
// box (CV_8UC1 of the box's size, the box clipped to the frame), so that an
// open stream holds its objects' pixels rather than a frame per object.
void CropMaskToBox(SegmentedObject& object);

// The mask of `held` (cropped, CropMaskToBox) at the frame's `size`.
cv::Mat MaskAtSize(const SegmentedObject& held, cv::Size size);

// How many pixels of `mask` (at the frame's size) lie on `held`'s cropped
// mask.
int OverlapWithHeld(const cv::Mat& mask, const SegmentedObject& held);

// Of a held object (CropMaskToBox), what a vote on cuts looks at: its
// mask, box and area (not its points or geometry, which a stream may ask
// for and a vote does not need to keep).
SegmentedObject OutlineOf(const SegmentedObject& held);

// Whether `cut` (objects held, CropMaskToBox) holds `a` and `b` (masks at
// the frame's size) as one: one of its objects covers more than half of
// each.
bool HeldAsOne(const std::vector<SegmentedObject>& cut,
               const SegmentedObject& a, const SegmentedObject& b);

// Joins the objects of `found` (masks at the frame's size) that more than
// half of `cuts` (other cuts of the same view, objects held) hold as one
// (HeldAsOne) and `may_join` allows, each group into its largest. How many
// objects were joined into others.
int JoinWhereMostHoldAsOne(
    const std::vector<std::vector<SegmentedObject>>& cuts,
    const std::function<bool(const SegmentedObject&, const SegmentedObject&)>&
        may_join,
    std::vector<SegmentedObject>& found);

// Of the pairs of pixels in a row or a column at most `reach` apart (1:
// 4-neighbours), one on `a`, the other on `b` (masks at the frame's size),
// both with depth in `depth` (CV_32FC1): how many, and how many `jump` says
// differ. A reach beyond 1 sees across a gap of reach - 1 pixels between
// the two.
struct BorderJumps {
  int pairs = 0;
  int jumps = 0;
};
BorderJumps CountBorderJumps(const SegmentedObject& a, const SegmentedObject& b,
                             const cv::Mat& depth,
                             const std::function<bool(float, float)>& jump,
                             int reach = 1);

// Whether two held objects (CropMaskToBox) of a frame of `size` touch, as
// Touch's.
bool HeldTouch(const SegmentedObject& a, const SegmentedObject& b,
               cv::Size size, int radius);

// Whether an object of `area` pixels is the whole of `pieces` (at least
// two) rather than one of them: nearer their summed area than the largest's.
bool IsWhole(int area, const std::vector<Piece>& pieces);

// The pieces of a joined object that came whole this frame (`was` last
// frame, its mask at the frame's size or cropped to its box; `now` in this
// one; their centroids in the world beside them),
// carried along with it: each piece moved by the whole's motion, in the
// world and (its box) in the image, and its area scaled as the whole's.
// A part that later moves apart is still told by its piece, and gets back
// the identity it had before it was joined.
void CarryPieces(const SegmentedObject& was, const Eigen::Vector3f& was_world,
                 const SegmentedObject& now, const Eigen::Vector3f& now_world,
                 std::vector<Piece>& pieces);

// Whether some object of this frame split off as a piece of identity
// `former_id` (split_from: per object, the piece it split off as).
bool SplitOffAs(const std::vector<std::optional<Piece>>& split_from,
                int former_id);

// The pieces of `before` with an identity of their own (former_id) that no
// piece of `now` has and no part of this frame took (`split_from`): each
// was hidden, or cut into the rest, this frame. They are carried along with
// the joined object (CarryPieces, from `was` to `object`) and added to
// `now`, so that the part is told when it comes back.
void CarryUnseenPieces(const std::vector<Piece>& before,
                       const std::vector<std::optional<Piece>>& split_from,
                       const SegmentedObject& was,
                       const Eigen::Vector3f& was_world,
                       const SegmentedObject& object,
                       const Eigen::Vector3f& world, std::vector<Piece>& now);

}  // namespace fovea

#endif  // FOVEA_CORE_TRACK_OBJECT_OPS_H_
