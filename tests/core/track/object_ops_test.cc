// The tracker's operations on one frame's objects, on hand-made masks.

#include "core/track/object_ops.h"

#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/imgproc.hpp>
#include <vector>

namespace fovea {
namespace {

SegmentedObject Square(int x, int y, int side,
                       const Eigen::Vector3f& centroid) {
  SegmentedObject o;
  o.mask = cv::Mat(20, 20, CV_8UC1, cv::Scalar(0));
  o.box = cv::Rect(x, y, side, side);
  o.mask(o.box).setTo(255);
  o.area = side * side;
  o.centroid = centroid;
  o.extent = Eigen::Vector3f(0.01f, 0.02f, 0.03f) * static_cast<float>(side);
  return o;
}

// Square(...) as a piece, its centroid in the world `centroid`.
Piece SquarePiece(int x, int y, int side, const Eigen::Vector3f& centroid) {
  return PieceOf(Square(x, y, side, centroid), centroid);
}

TEST(ObjectOps, SquaresTwoPixelsApartTouchWhenOneGrowsByThree) {
  // Columns 2-4 and 7-9: a gap of columns 5 and 6, which a grown by 2
  // fills; by 3 it reaches column 7.
  const SegmentedObject a = Square(2, 2, 3, Eigen::Vector3f::Zero());
  const SegmentedObject b = Square(7, 2, 3, Eigen::Vector3f::Zero());
  EXPECT_FALSE(Touch(a.mask, a.box, b.mask, b.box, 2));
  EXPECT_TRUE(Touch(a.mask, a.box, b.mask, b.box, 3));
  EXPECT_TRUE(Touch(b.mask, b.box, a.mask, a.box, 3));
}

TEST(ObjectOps, JoiningIsTheUnionWithAnAreaWeightedCentroid) {
  SegmentedObject into = Square(0, 0, 4, Eigen::Vector3f(0, 0, 1));  // 16 px
  const SegmentedObject piece = Square(10, 10, 2, Eigen::Vector3f(1, 0, 1));
  Join(piece, into);
  EXPECT_EQ(into.area, 20);
  EXPECT_EQ(into.box, cv::Rect(0, 0, 12, 12));
  EXPECT_NEAR(into.centroid.x(), 4.0f / 20.0f, 1e-6f);
  EXPECT_FLOAT_EQ(into.extent.z(), 0.12f);  // the larger
  EXPECT_FALSE(into.geometry.has_value());
}

TEST(ObjectOps, AppearanceTellsColoursApartNotShapes) {
  cv::Mat color(20, 20, CV_8UC3, cv::Scalar(200, 30, 30));        // red (RGB)
  color(cv::Rect(10, 0, 10, 20)).setTo(cv::Scalar(30, 30, 200));  // blue
  const SegmentedObject red_square = Square(1, 1, 6, Eigen::Vector3f::Zero());
  SegmentedObject red_bar = Square(0, 10, 2, Eigen::Vector3f::Zero());
  red_bar.mask(cv::Rect(0, 10, 8, 2)).setTo(255);
  red_bar.box = cv::Rect(0, 10, 8, 2);
  const SegmentedObject blue = Square(12, 4, 5, Eigen::Vector3f::Zero());
  const cv::Mat a = Appearance(color, red_square);
  const cv::Mat b = Appearance(color, red_bar);
  const cv::Mat c = Appearance(color, blue);
  ASSERT_FALSE(a.empty());
  EXPECT_NEAR(cv::compareHist(a, b, cv::HISTCMP_BHATTACHARYYA), 0.0, 1e-6);
  EXPECT_NEAR(cv::compareHist(a, c, cv::HISTCMP_BHATTACHARYYA), 1.0, 1e-6);
  EXPECT_TRUE(Appearance(cv::Mat(), red_square).empty());
}

TEST(ObjectOps, CoordinateMedianIsTakenPerAxis) {
  const Eigen::Vector3f m = CoordinateMedian({{1, 9, 0}, {5, 1, 2}, {3, 4, 1}});
  EXPECT_EQ(m, Eigen::Vector3f(3, 4, 1));
  EXPECT_EQ(CoordinateMedian({}), Eigen::Vector3f::Zero());
}

TEST(ObjectOps, APieceIsTheOverlappingOneOfItsSizeNearest) {
  // Last frame's pieces: a 4x4 square at (0,0) and a 4x4 at (4,0) beside
  // it, and a 9x9 one covering both.
  const std::vector<Piece> before = {
      SquarePiece(0, 0, 4, Eigen::Vector3f(0.00f, 0, 1)),
      SquarePiece(4, 0, 4, Eigen::Vector3f(0.05f, 0, 1)),
      SquarePiece(0, 0, 9, Eigen::Vector3f(0.02f, 0, 1))};
  ASSERT_EQ(before[0].box, cv::Rect(0, 0, 4, 4));
  EXPECT_EQ(before[0].mask.size(), cv::Size(4, 4));
  EXPECT_EQ(before[0].area, 16);
  // A 4x4 square 1 px right of the first overlaps all three: the big one
  // is more than 1.5x its size, and the first is nearer than the second.
  const Piece moved = SquarePiece(1, 0, 4, Eigen::Vector3f(0.01f, 0, 1));
  EXPECT_EQ(MatchingPiece(moved, Eigen::Vector3f::Zero(), before), 0);
  // Of two the same size it overlaps, the nearer after the camera's own
  // motion (`shift`) is taken out.
  const Piece between = SquarePiece(3, 0, 6, Eigen::Vector3f(0.05f, 0, 1));
  EXPECT_EQ(
      MatchingPiece(between, Eigen::Vector3f::Zero(), {before[0], before[1]}),
      -1);  // 36 px against 16: none is its size
  const Piece small = SquarePiece(2, 0, 4, Eigen::Vector3f(0.05f, 0, 1));
  const std::vector<Piece> pair = {before[0], before[1]};
  EXPECT_EQ(MatchingPiece(small, Eigen::Vector3f::Zero(), pair), 1);
  EXPECT_EQ(MatchingPiece(small, Eigen::Vector3f(0.05f, 0, 0), pair), 0);
  // Nothing overlaps: none.
  const Piece away = SquarePiece(14, 14, 4, Eigen::Vector3f(0, 0, 1));
  EXPECT_EQ(MatchingPiece(away, Eigen::Vector3f::Zero(), before), -1);
}

TEST(ObjectOps, PiecesOfAWholeAreCarriedAlongWithIt) {
  // Two 4x4 pieces side by side, joined: an 8x4 whole at (0,0). It comes
  // whole next frame, 5 px right and 5 px down, 3 cm along x in the world,
  // and 1.5 times its area (the camera came closer).
  const std::vector<Piece> was = {
      SquarePiece(0, 0, 4, Eigen::Vector3f(0.00f, 0, 1)),
      SquarePiece(4, 0, 4, Eigen::Vector3f(0.02f, 0, 1))};
  SegmentedObject whole = Square(0, 0, 4, Eigen::Vector3f(0.01f, 0, 1));
  Join(Square(4, 0, 4, Eigen::Vector3f(0.02f, 0, 1)), whole);
  SegmentedObject now;
  now.mask = cv::Mat(20, 20, CV_8UC1, cv::Scalar(0));
  now.box = cv::Rect(3, 5, 12, 4);  // 48 px, centroid (8.5, 6.5)
  now.mask(now.box).setTo(255);
  now.area = 48;
  std::vector<Piece> pieces = was;
  CarryPieces(whole, Eigen::Vector3f(0.01f, 0, 1), now,
              Eigen::Vector3f(0.04f, 0, 1), pieces);
  // The whole's centroid went from (3.5, 1.5) to (8.5, 6.5).
  EXPECT_EQ(pieces[0].box, cv::Rect(5, 5, 4, 4));
  EXPECT_EQ(pieces[1].box, cv::Rect(9, 5, 4, 4));
  EXPECT_TRUE(pieces[0].world_centroid.isApprox(Eigen::Vector3f(0.03f, 0, 1)));
  EXPECT_TRUE(pieces[1].world_centroid.isApprox(Eigen::Vector3f(0.05f, 0, 1)));
  EXPECT_EQ(pieces[0].area, 24);  // 16 x 48 / 32
  EXPECT_EQ(pieces[1].mask.size(), cv::Size(4, 4));
  // Each part of the whole, where the whole went, is still its own piece.
  const Piece left = SquarePiece(5, 5, 5, Eigen::Vector3f(0.03f, 0, 1));
  const Piece right = SquarePiece(9, 5, 5, Eigen::Vector3f(0.05f, 0, 1));
  EXPECT_EQ(MatchingPiece(left, Eigen::Vector3f::Zero(), pieces), 0);
  EXPECT_EQ(MatchingPiece(right, Eigen::Vector3f::Zero(), pieces), 1);
}

TEST(ObjectOps, PiecesMovedAsOneOfThemMovedFindASmallPartThatMovedFar) {
  // A 6x6 piece at (0,0) and a 2x2 one beside it at (6,0), pushed along
  // together 4 px right and 3 cm in the world: the small part, now at
  // (10,0), no longer overlaps its piece, which lay where it was.
  const std::vector<Piece> before = {
      SquarePiece(0, 0, 6, Eigen::Vector3f(0.00f, 0, 1)),
      SquarePiece(6, 0, 2, Eigen::Vector3f(0.02f, 0, 1))};
  const Piece large = SquarePiece(4, 0, 6, Eigen::Vector3f(0.03f, 0, 1));
  const Piece small = SquarePiece(10, 0, 2, Eigen::Vector3f(0.05f, 0, 1));
  EXPECT_EQ(MatchingPiece(small, Eigen::Vector3f::Zero(), before), -1);
  // Moved as the large one moved (its mask's centroid 4 px right, 3 cm),
  // the small piece is at (10,0) and 5 cm again.
  const std::vector<Piece> moved =
      MovedAs(before, before[0], large, Eigen::Vector3f::Zero());
  EXPECT_EQ(moved[1].box, cv::Rect(10, 0, 2, 2));
  EXPECT_TRUE(moved[1].world_centroid.isApprox(Eigen::Vector3f(0.05f, 0, 1)));
  EXPECT_EQ(moved[1].area, 4);
  EXPECT_EQ(MatchingPiece(small, Eigen::Vector3f::Zero(), moved), 1);
  // The camera's own motion is not the pieces': with the camera moved by
  // 3 cm, the large one did not move in the world.
  const std::vector<Piece> still =
      MovedAs(before, before[0], large, Eigen::Vector3f(0.03f, 0, 0));
  EXPECT_TRUE(still[1].world_centroid.isApprox(Eigen::Vector3f(0.02f, 0, 1)));
  EXPECT_EQ(still[1].box, cv::Rect(10, 0, 2, 2));  // the image moved
}

TEST(ObjectOps, AnUnseenPieceWithAnIdentityIsCarriedAlong) {
  // A joined object: its own 4x4 piece at (0,0) and one that was object 5
  // at (4,0). This frame the object is its own part only, 5 px right
  // (0.03 m in the world): piece 5 is no part of the frame, so it is
  // carried along to (9,0), while the own piece is this frame's.
  std::vector<Piece> before = {
      SquarePiece(0, 0, 4, Eigen::Vector3f(0.00f, 0, 1)),
      SquarePiece(4, 0, 4, Eigen::Vector3f(0.02f, 0, 1))};
  before[1].former_id = 5;
  const SegmentedObject was = Square(0, 0, 4, Eigen::Vector3f(0.00f, 0, 1));
  const SegmentedObject object = Square(5, 0, 4, Eigen::Vector3f(0.03f, 0, 1));
  const std::vector<Piece> own = {
      PieceOf(object, Eigen::Vector3f(0.03f, 0, 1))};
  std::vector<Piece> now = own;
  CarryUnseenPieces(before, {std::nullopt}, was, Eigen::Vector3f(0, 0, 1),
                    object, Eigen::Vector3f(0.03f, 0, 1), now);
  ASSERT_EQ(now.size(), 2u);
  EXPECT_EQ(now[0].former_id, 0);
  EXPECT_EQ(now[1].former_id, 5);
  EXPECT_EQ(now[1].box, cv::Rect(9, 0, 4, 4));
  EXPECT_TRUE(now[1].world_centroid.isApprox(Eigen::Vector3f(0.05f, 0, 1)));
  // Not when a part of the frame is piece 5 already, nor when one split
  // off as it.
  std::vector<Piece> seen = now;
  CarryUnseenPieces(before, {std::nullopt}, was, Eigen::Vector3f(0, 0, 1),
                    object, Eigen::Vector3f(0.03f, 0, 1), seen);
  EXPECT_EQ(seen.size(), 2u);
  std::vector<Piece> split = own;
  CarryUnseenPieces(before, {std::nullopt, before[1]}, was,
                    Eigen::Vector3f(0, 0, 1), object,
                    Eigen::Vector3f(0.03f, 0, 1), split);
  EXPECT_EQ(split.size(), 1u);
}

TEST(ObjectOps, AHeldObjectKeepsOnlyItsBoxAndOverlapsAsBefore) {
  // A 4x4 square at (6,3) in a 20x20 frame, held cropped: 16 bytes, not
  // 400, and the same pixels at the frame's size again.
  const SegmentedObject square = Square(6, 3, 4, Eigen::Vector3f(0, 0, 1));
  SegmentedObject held = square;
  CropMaskToBox(held);
  EXPECT_EQ(held.mask.size(), cv::Size(4, 4));
  EXPECT_EQ(held.box, cv::Rect(6, 3, 4, 4));
  EXPECT_EQ(cv::countNonZero(MaskAtSize(held, cv::Size(20, 20)) != square.mask),
            0);
  // A 4x4 square 2 px right overlaps it on 2 x 4 pixels; one far away on
  // none; the whole frame on all 16.
  EXPECT_EQ(OverlapWithHeld(Square(8, 3, 4, {}).mask, held), 8);
  EXPECT_EQ(OverlapWithHeld(Square(14, 14, 4, {}).mask, held), 0);
  EXPECT_EQ(OverlapWithHeld(cv::Mat(20, 20, CV_8UC1, cv::Scalar(255)), held),
            16);
  // A box reaching past the frame is clipped to it.
  SegmentedObject edge = Square(16, 16, 4, {});
  edge.box = cv::Rect(16, 16, 6, 6);
  CropMaskToBox(edge);
  EXPECT_EQ(edge.box, cv::Rect(16, 16, 4, 4));
  EXPECT_EQ(OverlapWithHeld(Square(16, 16, 4, {}).mask, edge), 16);
  // Its pieces are carried as from the mask at the frame's size.
  SegmentedObject moved = Square(9, 5, 4, Eigen::Vector3f(0.01f, 0, 1));
  std::vector<Piece> from_held = {PieceOf(square, Eigen::Vector3f(0, 0, 1))};
  std::vector<Piece> from_full = from_held;
  CarryPieces(held, Eigen::Vector3f(0, 0, 1), moved,
              Eigen::Vector3f(0.01f, 0, 1), from_held);
  CarryPieces(square, Eigen::Vector3f(0, 0, 1), moved,
              Eigen::Vector3f(0.01f, 0, 1), from_full);
  EXPECT_EQ(from_held[0].box, cv::Rect(9, 5, 4, 4));
  EXPECT_EQ(from_held[0].box, from_full[0].box);
}

// A square at (x, y), its centroid the origin.
SegmentedObject Sq(int x, int y, int side) {
  return Square(x, y, side, Eigen::Vector3f::Zero());
}

// A 4 x 8 rectangle at (x, y) of a 20 x 20 frame.
SegmentedObject Wide(int x, int y) {
  SegmentedObject o = Sq(x, y, 4);
  o.box = cv::Rect(x, y, 8, 4);
  o.mask(o.box).setTo(255);
  o.area = 32;
  return o;
}

// `o` held, as a cut kept for a vote holds it.
SegmentedObject Held(SegmentedObject o) {
  CropMaskToBox(o);
  return o;
}

TEST(ObjectOps, TwoObjectsAreHeldAsOneWhenOneObjectCoversMostOfEach) {
  // The halves of a 4 x 8 rectangle at (2,2): the whole covers both; a
  // square on the left half covers it but not the right; two squares one
  // each, neither both.
  const SegmentedObject left = Sq(2, 2, 4);
  const SegmentedObject right = Sq(6, 2, 4);
  EXPECT_TRUE(HeldAsOne({Held(Wide(2, 2))}, left, right));
  EXPECT_FALSE(HeldAsOne({Held(Sq(2, 2, 4))}, left, right));
  EXPECT_FALSE(HeldAsOne({Held(Sq(2, 2, 4)), Held(Sq(6, 2, 4))}, left, right));
  // Covering 3 of the right half's 4 columns is more than half of it.
  EXPECT_TRUE(HeldAsOne({Held(Wide(1, 2))}, left, right));
  // 2 of its 4 columns are not.
  EXPECT_FALSE(HeldAsOne({Held(Wide(0, 2))}, left, right));
}

// Any two objects may join.
bool kAny(const SegmentedObject&, const SegmentedObject&) { return true; }

TEST(ObjectOps, ObjectsMostOtherCutsHoldAsOneAreJoinedIntoTheLargest) {
  // The cut to mend: a rectangle's halves (the right one larger), and a
  // square apart. Of three other cuts, two hold the rectangle whole and
  // one in halves: the halves join, under the larger's place in the
  // list; the square stays.
  const auto mend = [] {
    SegmentedObject right = Sq(6, 2, 4);
    right.mask(cv::Rect(6, 6, 4, 1)).setTo(255);
    right.box = cv::Rect(6, 2, 4, 5);
    right.area = 20;
    return std::vector<SegmentedObject>{Sq(2, 2, 4), right, Sq(14, 14, 4)};
  };
  const std::vector<SegmentedObject> whole = {Held(Wide(2, 2)),
                                              Held(Sq(14, 14, 4))};
  const std::vector<SegmentedObject> halves = {
      Held(Sq(2, 2, 4)), Held(Sq(6, 2, 4)), Held(Sq(14, 14, 4))};
  std::vector<SegmentedObject> found = mend();
  EXPECT_EQ(JoinWhereMostHoldAsOne({whole, halves, whole}, kAny, found), 1);
  ASSERT_EQ(found.size(), 2u);
  EXPECT_EQ(found[0].area, 36);
  EXPECT_EQ(found[0].box, cv::Rect(2, 2, 8, 5));
  EXPECT_EQ(found[1].box, cv::Rect(14, 14, 4, 4));
  // One of three, or two of four, is no majority.
  found = mend();
  EXPECT_EQ(JoinWhereMostHoldAsOne({whole, halves, halves}, kAny, found), 0);
  EXPECT_EQ(found.size(), 3u);
  EXPECT_EQ(JoinWhereMostHoldAsOne({whole, halves, halves, whole}, kAny, found),
            0);
  EXPECT_EQ(found.size(), 3u);
  // No other cut: nothing joins.
  EXPECT_EQ(JoinWhereMostHoldAsOne({}, kAny, found), 0);
  // Nor when `may_join` forbids it.
  EXPECT_EQ(
      JoinWhereMostHoldAsOne(
          {whole, halves, whole},
          [](const SegmentedObject&, const SegmentedObject&) { return false; },
          found),
      0);
  EXPECT_EQ(found.size(), 3u);
}

TEST(ObjectOps, TheBorderBetweenTwoObjectsIsCountedInPairsOfNeighbours) {
  // Two 4 x 4 squares side by side: 4 pairs across their shared border.
  // At one depth none jumps; with the right one 5 cm further, all do, but
  // for a row with no depth on it.
  const SegmentedObject left = Sq(2, 2, 4);
  const SegmentedObject right = Sq(6, 2, 4);
  cv::Mat depth(20, 20, CV_32FC1, cv::Scalar(1.0f));
  const auto beyond_1cm = [](float z, float z2) {
    return std::abs(z - z2) > 0.01f;
  };
  BorderJumps border = CountBorderJumps(left, right, depth, beyond_1cm);
  EXPECT_EQ(border.pairs, 4);
  EXPECT_EQ(border.jumps, 0);
  depth(right.box).setTo(1.05f);
  depth.row(3).setTo(0.0f);
  border = CountBorderJumps(right, left, depth, beyond_1cm);
  EXPECT_EQ(border.pairs, 3);
  EXPECT_EQ(border.jumps, 3);
  // Squares apart share no border.
  EXPECT_EQ(CountBorderJumps(left, Sq(14, 14, 4), depth, beyond_1cm).pairs, 0);
  // With a gap of two pixels between them (columns 6 and 7), 4-neighbours
  // see none of it; a reach of 3 sees the pairs 3 apart across it, one a
  // row (but for the row with no depth), all jumps.
  const SegmentedObject gapped = Sq(8, 2, 4);
  depth(gapped.box).setTo(1.05f);
  EXPECT_EQ(CountBorderJumps(left, gapped, depth, beyond_1cm).pairs, 0);
  border = CountBorderJumps(left, gapped, depth, beyond_1cm, 3);
  EXPECT_EQ(border.pairs, 3);
  EXPECT_EQ(border.jumps, 3);
}

}  // namespace
}  // namespace fovea
