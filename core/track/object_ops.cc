#include "core/track/object_ops.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <optional>

namespace fovea {

Eigen::Vector3f CoordinateMedian(std::vector<Eigen::Vector3f> v) {
  Eigen::Vector3f m = Eigen::Vector3f::Zero();
  if (v.empty()) return m;
  for (int axis = 0; axis < 3; ++axis) {
    auto mid = v.begin() + static_cast<ptrdiff_t>(v.size() / 2);
    std::nth_element(
        v.begin(), mid, v.end(),
        [axis](const Eigen::Vector3f& a, const Eigen::Vector3f& b) {
          return a[axis] < b[axis];
        });
    m[axis] = (*mid)[axis];
  }
  return m;
}

bool Touch(const cv::Mat& a, const cv::Rect& a_box, const cv::Mat& b,
           const cv::Rect& b_box, int radius) {
  const cv::Rect grown = Grown(a_box, radius) & cv::Rect(0, 0, a.cols, a.rows);
  const cv::Rect both = grown & b_box;
  if (both.empty()) return false;
  cv::Mat dilated;
  cv::dilate(a(grown), dilated,
             cv::getStructuringElement(
                 cv::MORPH_ELLIPSE, cv::Size(2 * radius + 1, 2 * radius + 1)));
  const cv::Rect local(both.x - grown.x, both.y - grown.y, both.width,
                       both.height);
  cv::Mat overlap;
  cv::bitwise_and(dilated(local), b(both), overlap);
  return cv::countNonZero(overlap) > 0;
}

void Join(const SegmentedObject& piece, SegmentedObject& into) {
  const double total = static_cast<double>(into.area) + piece.area;
  if (total > 0) {
    into.centroid = ((into.centroid * static_cast<float>(into.area)) +
                     (piece.centroid * static_cast<float>(piece.area))) /
                    static_cast<float>(total);
  }
  into.extent = into.extent.cwiseMax(piece.extent);
  cv::bitwise_or(into.mask, piece.mask, into.mask);
  into.box = into.box | piece.box;
  into.area = cv::countNonZero(into.mask);
  into.geometry.reset();  // the pieces' boxes are not the whole's
  into.point_indices.insert(into.point_indices.end(),
                            piece.point_indices.begin(),
                            piece.point_indices.end());
  into.points.insert(into.points.end(), piece.points.begin(),
                     piece.points.end());
}

cv::Mat Appearance(const cv::Mat& color, const SegmentedObject& object) {
  if (color.empty() || color.type() != CV_8UC3 || object.mask.empty() ||
      color.size() != object.mask.size()) {
    return {};
  }
  const cv::Rect box = object.box & cv::Rect(0, 0, color.cols, color.rows);
  if (box.empty()) return {};
  const cv::Mat image = color(box);
  const cv::Mat mask = object.mask(box);
  const int channels[] = {0, 1, 2};
  const int bins[] = {4, 4, 4};
  const float range[] = {0.0f, 256.0f};
  const float* ranges[] = {range, range, range};
  cv::Mat histogram;
  cv::calcHist(&image, 1, channels, mask, histogram, 3, bins, ranges);
  if (cv::sum(histogram)[0] <= 0.0) return {};
  return histogram;
}

Piece PieceOf(const SegmentedObject& object,
              const Eigen::Vector3f& world_centroid) {
  Piece piece;
  piece.box = object.box & cv::Rect(0, 0, object.mask.cols, object.mask.rows);
  if (!piece.box.empty()) piece.mask = object.mask(piece.box).clone();
  piece.area = object.area;
  piece.world_centroid = world_centroid;
  return piece;
}

int MatchingPiece(const Piece& now, const Eigen::Vector3f& shift,
                  const std::vector<Piece>& before) {
  int best = -1;
  float nearest = 0.0f;
  if (now.mask.empty() || now.area <= 0) return best;
  for (int i = 0; i < static_cast<int>(before.size()); ++i) {
    const Piece& p = before[i];
    if (p.mask.empty() || p.area <= 0 || 2 * now.area > 3 * p.area ||
        2 * p.area > 3 * now.area) {
      continue;
    }
    const cv::Rect both = p.box & now.box;
    if (both.empty()) continue;
    cv::Mat overlap;
    cv::bitwise_and(now.mask(both - now.box.tl()), p.mask(both - p.box.tl()),
                    overlap);
    if (cv::countNonZero(overlap) == 0) continue;
    const float d = (now.world_centroid - shift - p.world_centroid).norm();
    if (best < 0 || d < nearest) {
      best = i;
      nearest = d;
    }
  }
  return best;
}

namespace {

// The centroid of `mask` (CV_8UC1) placed at `box` in the frame, in pixels;
// nullopt when it has no pixel.
std::optional<cv::Point2d> MaskCentroid(const cv::Mat& mask,
                                        const cv::Rect& box) {
  if (mask.empty()) return std::nullopt;
  const cv::Moments m = cv::moments(mask, true);
  if (m.m00 <= 0.0) return std::nullopt;
  return cv::Point2d(box.x + m.m10 / m.m00, box.y + m.m01 / m.m00);
}

// The whole pixels from `from` to `to` (none when either is missing).
cv::Point PixelShift(const std::optional<cv::Point2d>& from,
                     const std::optional<cv::Point2d>& to) {
  if (!from || !to) return {0, 0};
  return {static_cast<int>(std::lround(to->x - from->x)),
          static_cast<int>(std::lround(to->y - from->y))};
}

}  // namespace

std::vector<Piece> MovedAs(const std::vector<Piece>& pieces, const Piece& from,
                           const Piece& to, const Eigen::Vector3f& shift) {
  const Eigen::Vector3f motion =
      to.world_centroid - shift - from.world_centroid;
  const cv::Point pixels = PixelShift(MaskCentroid(from.mask, from.box),
                                      MaskCentroid(to.mask, to.box));
  std::vector<Piece> moved = pieces;
  for (Piece& p : moved) {
    p.world_centroid += motion;
    p.box += pixels;
  }
  return moved;
}

bool SplitOffAs(const std::vector<std::optional<Piece>>& split_from,
                int former_id) {
  return std::any_of(split_from.begin(), split_from.end(),
                     [&](const std::optional<Piece>& p) {
                       return p && p->former_id == former_id;
                     });
}

void CarryUnseenPieces(const std::vector<Piece>& before,
                       const std::vector<std::optional<Piece>>& split_from,
                       const SegmentedObject& was,
                       const Eigen::Vector3f& was_world,
                       const SegmentedObject& object,
                       const Eigen::Vector3f& world, std::vector<Piece>& now) {
  std::vector<Piece> unseen;
  for (const Piece& p : before) {
    if (p.former_id == 0) continue;
    const auto same = [&](const Piece& q) {
      return q.former_id == p.former_id;
    };
    if (std::none_of(now.begin(), now.end(), same) &&
        !SplitOffAs(split_from, p.former_id)) {
      unseen.push_back(p);
    }
  }
  if (unseen.empty()) return;
  CarryPieces(was, was_world, object, world, unseen);
  now.insert(now.end(), unseen.begin(), unseen.end());
}

void KeepFormerIds(const Eigen::Vector3f& shift,
                   const std::vector<Piece>& before, std::vector<Piece>& now) {
  for (Piece& p : now) {
    if (p.former_id != 0) continue;
    const int was = MatchingPiece(p, shift, before);
    if (was < 0) continue;
    p.former_id = before[was].former_id;
    p.former_frames_seen = before[was].former_frames_seen;
  }
}

namespace {

// The centroid of `object`'s mask (at the frame's size, or cropped to its
// box) in pixels; nullopt when it has none.
std::optional<cv::Point2d> PixelCentroid(const SegmentedObject& object) {
  const bool cropped = object.mask.size() == object.box.size();
  const cv::Rect box =
      cropped ? object.box
              : object.box & cv::Rect(0, 0, object.mask.cols, object.mask.rows);
  if (box.empty()) return std::nullopt;
  return MaskCentroid(cropped ? object.mask : object.mask(box), box);
}

}  // namespace

void CropMaskToBox(SegmentedObject& object) {
  object.box &= cv::Rect(0, 0, object.mask.cols, object.mask.rows);
  object.mask =
      object.box.empty() ? cv::Mat() : object.mask(object.box).clone();
}

cv::Mat MaskAtSize(const SegmentedObject& held, cv::Size size) {
  cv::Mat mask(size, CV_8UC1, cv::Scalar(0));
  const cv::Rect box = held.box & cv::Rect(cv::Point(0, 0), size);
  if (!box.empty() && held.mask.size() == held.box.size()) {
    held.mask(box - held.box.tl()).copyTo(mask(box));
  }
  return mask;
}

int OverlapWithHeld(const cv::Mat& mask, const SegmentedObject& held) {
  const cv::Rect box = held.box & cv::Rect(0, 0, mask.cols, mask.rows);
  if (box.empty() || held.mask.size() != held.box.size()) return 0;
  cv::Mat both;
  cv::bitwise_and(mask(box), held.mask(box - held.box.tl()), both);
  return cv::countNonZero(both);
}

SegmentedObject OutlineOf(const SegmentedObject& held) {
  SegmentedObject outline;
  outline.mask = held.mask;
  outline.box = held.box;
  outline.area = held.area;
  return outline;
}

bool HeldAsOne(const std::vector<SegmentedObject>& cut,
               const SegmentedObject& a, const SegmentedObject& b) {
  return std::any_of(cut.begin(), cut.end(), [&](const SegmentedObject& o) {
    return 2 * OverlapWithHeld(a.mask, o) > a.area &&
           2 * OverlapWithHeld(b.mask, o) > b.area;
  });
}

BorderJumps CountBorderJumps(const SegmentedObject& a, const SegmentedObject& b,
                             const cv::Mat& depth,
                             const std::function<bool(float, float)>& jump,
                             int reach) {
  BorderJumps out;
  const cv::Rect frame(0, 0, depth.cols, depth.rows);
  const cv::Rect near = Grown(a.box, reach) & Grown(b.box, reach) & frame;
  const auto pair = [&](int u, int v, int u2, int v2) {
    const bool ab = a.mask.at<uint8_t>(v, u) && b.mask.at<uint8_t>(v2, u2);
    const bool ba = b.mask.at<uint8_t>(v, u) && a.mask.at<uint8_t>(v2, u2);
    if (!ab && !ba) return;
    const float z = depth.at<float>(v, u);
    const float z2 = depth.at<float>(v2, u2);
    if (!(z > 0.0f) || !(z2 > 0.0f)) return;
    ++out.pairs;
    if (jump(z, z2)) ++out.jumps;
  };
  for (int v = near.y; v < near.y + near.height; ++v) {
    for (int u = near.x; u < near.x + near.width; ++u) {
      for (int d = 1; d <= reach; ++d) {
        if (u + d < frame.width) pair(u, v, u + d, v);
        if (v + d < frame.height) pair(u, v, u, v + d);
      }
    }
  }
  return out;
}

int JoinWhereMostHoldAsOne(
    const std::vector<std::vector<SegmentedObject>>& cuts,
    const std::function<bool(const SegmentedObject&, const SegmentedObject&)>&
        may_join,
    std::vector<SegmentedObject>& found) {
  // Groups by union-find; each group's root its largest object.
  std::vector<size_t> root(found.size());
  for (size_t i = 0; i < root.size(); ++i) root[i] = i;
  const auto find = [&root](size_t i) {
    while (root[i] != i) i = root[i] = root[root[i]];
    return i;
  };
  for (size_t a = 0; a < found.size(); ++a) {
    for (size_t b = a + 1; b < found.size(); ++b) {
      const size_t ra = find(a);
      const size_t rb = find(b);
      if (ra == rb) continue;
      const auto as_one = std::count_if(
          cuts.begin(), cuts.end(), [&](const std::vector<SegmentedObject>& c) {
            return HeldAsOne(c, found[a], found[b]);
          });
      if (2 * static_cast<size_t>(as_one) <= cuts.size() ||
          !may_join(found[a], found[b])) {
        continue;
      }
      if (found[ra].area >= found[rb].area) {
        root[rb] = ra;
      } else {
        root[ra] = rb;
      }
    }
  }
  int joined = 0;
  for (size_t i = 0; i < found.size(); ++i) {
    if (find(i) == i) continue;
    Join(found[i], found[find(i)]);
    ++joined;
  }
  std::vector<SegmentedObject> kept;
  for (size_t i = 0; i < found.size(); ++i) {
    if (find(i) == i) kept.push_back(std::move(found[i]));
  }
  found = std::move(kept);
  return joined;
}

bool HeldTouch(const SegmentedObject& a, const SegmentedObject& b,
               cv::Size size, int radius) {
  // Masks at the frame's size only for boxes that come near.
  if ((Grown(a.box, radius) & b.box).empty()) return false;
  return Touch(MaskAtSize(a, size), a.box, MaskAtSize(b, size), b.box, radius);
}

bool IsWhole(int area, const std::vector<Piece>& pieces) {
  if (pieces.size() < 2) return false;
  int sum = 0;
  int largest = 0;
  for (const Piece& p : pieces) {
    sum += p.area;
    largest = std::max(largest, p.area);
  }
  return 2 * area > sum + largest;
}

void CarryPieces(const SegmentedObject& was, const Eigen::Vector3f& was_world,
                 const SegmentedObject& now, const Eigen::Vector3f& now_world,
                 std::vector<Piece>& pieces) {
  const cv::Point shift = PixelShift(PixelCentroid(was), PixelCentroid(now));
  const double scale =
      was.area > 0 ? static_cast<double>(now.area) / was.area : 1.0;
  for (Piece& p : pieces) {
    p.world_centroid += now_world - was_world;
    p.box += shift;
    p.area = static_cast<int>(std::lround(p.area * scale));
  }
}

}  // namespace fovea
