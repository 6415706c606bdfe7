// The tracker's rules on pieces (tracker.h): pieces that moved together
// join, a joined track's parts that moved apart split, a track whose last
// mask one object covers joins it.

#include <algorithm>
#include <opencv2/core.hpp>
#include <utility>

#include "core/track/object_ops.h"
#include "core/track/tracker.h"

namespace fovea {

void Tracker::JoinAndSplit(
    const std::optional<Eigen::Isometry3f>& camera_to_world, Association& a,
    std::vector<Track>& tracks, TrackedFrame& out) const {
  // Pieces that moved together: join the smaller into the larger.
  std::vector<SegmentedObject>& found = a.found;
  std::vector<Eigen::Vector3f>& world = a.world;
  const Eigen::Vector3f& shift = a.shift;
  std::vector<int>& track_of = a.track_of;
  const std::vector<Eigen::Vector3f>& displacement = a.displacement;
  std::vector<TrackState>& state = a.state;
  const cv::Mat& depth = a.depth;
  std::vector<bool>& absorbed = a.absorbed;
  absorbed.assign(found.size(), false);
  std::vector<bool>& composite = a.composite;
  composite.assign(found.size(), false);
  // Each object's pieces: itself, and what joins it.
  std::vector<std::vector<Piece>>& pieces = a.pieces;
  pieces.assign(found.size(), {});
  for (size_t j = 0; j < found.size(); ++j) {
    pieces[j].push_back(PieceOf(found[j], world[j]));
  }
  // Object `piece` joins object `into` of this frame.
  const auto join = [&](size_t piece, size_t into) {
    Join(found[piece], found[into]);
    pieces[into].insert(pieces[into].end(), pieces[piece].begin(),
                        pieces[piece].end());
    composite[into] = true;
    world[into] = ToWorld(camera_to_world, found[into].centroid);
    absorbed[piece] = true;
  };
  for (size_t a = 0; a < found.size(); ++a) {
    if (state[a] != TrackState::kMoved || absorbed[a]) continue;
    for (size_t b = 0; b < found.size(); ++b) {
      if (b == a || absorbed[b] || state[b] != TrackState::kMoved) continue;
      if ((displacement[a] - displacement[b]).norm() >
          options_.joint_motion_m) {
        continue;
      }
      if (!Touch(found[a].mask, found[a].box, found[b].mask, found[b].box, 3)) {
        continue;
      }
      // Not two objects one stands in front of (across the gap of up to 3
      // pixels that Touch allows).
      if (!options_.join_across_depth_edges &&
          DepthEdgeBetween(found[a], found[b], depth, 4)) {
        continue;
      }
      // The larger piece's identity stays (the older's at equal size): an
      // object cut in pieces goes on as its main part, and two objects
      // swept along as one as the one that covers the most of it.
      const bool a_keeps =
          found[a].area != found[b].area
              ? found[a].area > found[b].area
              : tracks[track_of[a]].id < tracks[track_of[b]].id;
      const size_t keep = a_keeps ? a : b;
      const size_t drop = a_keeps ? b : a;
      for (Piece& p : pieces[drop]) {
        p.former_id = tracks[track_of[drop]].id;
        p.former_frames_seen = tracks[track_of[drop]].frames_seen;
      }
      join(drop, keep);
      tracks[track_of[drop]].last_seen_frame = -1;  // forgotten
      tracks[track_of[drop]].id = 0;
      ++out.joined;
      if (drop == a) break;
    }
  }
  // Objects j (no track) and k (joined track t's): whether j is one of
  // t's pieces that moved with k's (1: INC cut the object in two again)
  // or apart from it and no longer touches it (0: they are two objects),
  // or moved otherwise than it while touching it still (2: the two parts
  // of two objects pushed along together, whose cut between them moved),
  // by their own pieces before this frame's joins; -1 when j or k is not
  // one of t's pieces. `piece` gets j's piece, `k_piece` k's.
  const auto moved_with = [&](size_t j, size_t k, const Track& t, int* piece,
                              int* k_piece) {
    const Piece& now_j = pieces[j].front();
    const Piece& now_k = pieces[k].front();
    const int pk = MatchingPiece(now_k, shift, t.pieces);
    if (pk < 0) return -1;
    int pj = MatchingPiece(now_j, shift, t.pieces);
    if (pj < 0 || pj == pk) {
      // j may have moved by more than its size: look for it among the
      // pieces moved as k's moved.
      pj = MatchingPiece(now_j, shift,
                         MovedAs(t.pieces, t.pieces[pk], now_k, shift));
    }
    if (pj < 0 || pj == pk) return -1;
    *piece = pj;
    *k_piece = pk;
    const Eigen::Vector3f motion_j =
        now_j.world_centroid - shift - t.pieces[pj].world_centroid;
    const Eigen::Vector3f motion_k =
        now_k.world_centroid - shift - t.pieces[pk].world_centroid;
    if ((motion_j - motion_k).norm() <= options_.joint_motion_m) return 1;
    // Parts of one object cut otherwise this time touch still.
    return Touch(found[j].mask, found[j].box, found[k].mask, found[k].box, 3)
               ? 2
               : 0;
  };
  // An object without a track that is one of a joined track's pieces, or
  // lies inside its last mask, is that track's again (INC cut it in two
  // again), unless the two moved apart: then it is an object of its own
  // (split). Per object that split off: the piece it was.
  std::vector<std::optional<Piece>>& split_from = a.split_from;
  split_from.assign(found.size(), std::nullopt);
  // j, one of track t's pieces, splits off from k, another: j goes on as
  // its piece, under the identity that piece had before it was joined, or
  // under t's own, and then k under its piece's.
  const auto split = [&](size_t j, size_t k, const Track& t, int piece,
                         int k_piece) {
    ++out.split;
    if (t.pieces[piece].former_id != 0) {
      split_from[j] = t.pieces[piece];
      return;
    }
    state[j] = StateOfMotion(world[j] - shift - t.pieces[piece].world_centroid);
    track_of[j] = track_of[k];
    track_of[k] = -1;
    split_from[k] = t.pieces[k_piece];
  };
  // Pairs of pieces that moved otherwise than each other while touching
  // still (moved_with's 2), j outside the track's last mask: settled once
  // the clearer cases have taken their pieces.
  struct MovedOtherwise {
    size_t j, k;
    int track, piece, k_piece;
  };
  std::vector<MovedOtherwise> moved_otherwise;  // rarely any
  for (size_t j = 0; j < found.size(); ++j) {
    if (absorbed[j] || track_of[j] >= 0 || split_from[j]) continue;
    for (size_t k = 0; k < found.size(); ++k) {
      if (k == j || absorbed[k] || track_of[k] < 0) continue;
      const Track& t = tracks[track_of[k]];
      if (!t.composite || t.object.mask.empty()) continue;
      int piece = -1;
      int k_piece = -1;
      const int with = moved_with(j, k, t, &piece, &k_piece);
      if (with == 0) {
        split(j, k, t, piece, k_piece);
        break;
      }
      // Mostly inside the track's last mask: one object cut in two again
      // (not counted when j joins k anyway).
      const bool inside =
          with != 1 &&
          OverlapWithHeld(found[j].mask, t.object) * 2 > found[j].area;
      if (with == 1 || inside) {
        join(j, k);
        break;
      }
      if (with == 2) {
        moved_otherwise.push_back({j, k, track_of[k], piece, k_piece});
      }
    }
  }
  // Such a pair is two objects pushed along together whose cut between
  // them moved: each part goes on as its piece, not as a new object, when
  // no other object took that piece (or, for the track's own piece, k's).
  for (const MovedOtherwise& m : moved_otherwise) {
    if (absorbed[m.j] || track_of[m.j] >= 0 || split_from[m.j] ||
        absorbed[m.k] || track_of[m.k] != m.track) {
      continue;
    }
    const Track& t = tracks[m.track];
    const Piece& piece = t.pieces[m.piece];
    const Piece& k_piece = t.pieces[m.k_piece];
    const Piece& leaving = piece.former_id != 0 ? piece : k_piece;
    if (leaving.former_id == 0 || SplitOffAs(split_from, leaving.former_id)) {
      continue;
    }
    split(m.j, m.k, t, m.piece, m.k_piece);
  }

  // Whether a track other than `except` seen last frame held more than half
  // of `beyond` pixels of `mask` in its last mask.
  const auto held_by_another = [&](const cv::Mat& mask, int beyond,
                                   int except) {
    for (size_t u = 0; u < tracks.size(); ++u) {
      const Track& other = tracks[u];
      if (static_cast<int>(u) == except || other.id == 0 ||
          other.last_seen_frame != frame_index_ - 1) {
        continue;
      }
      if (2 * OverlapWithHeld(mask, other.object) > beyond) return true;
    }
    return false;
  };

  // Where what changed is known (a still camera, or one moved by a known
  // pose; not a refined cut, which replaces the last one), an object
  // without a track whose pixels mostly did not change, lying mostly inside
  // the last mask of a track that an object it touches kept, is a piece of
  // that object: INC cut an unchanged object in two this time. It joins it
  // rather than appearing; so does one that is the part of the last mask
  // the kept object lacks and reaches beyond it where no other track was
  // (an object cut short before, whole now that its region is cut again).
  // An object that "moved" only by being a piece (its centroid is not the
  // whole's; inside the last mask, unchanged) counts as kept, and its state
  // is told again once the pieces are one.
  if (!a.changed.empty()) {
    const auto unchanged = [&](size_t j) {
      const cv::Rect box =
          found[j].box & cv::Rect(0, 0, a.changed.cols, a.changed.rows);
      cv::Mat moved;
      cv::bitwise_and(a.changed(box), found[j].mask(box), moved);
      return 2 * cv::countNonZero(moved) < found[j].area;
    };
    for (size_t j = 0; j < found.size(); ++j) {
      if (absorbed[j] || track_of[j] >= 0 || split_from[j] || !unchanged(j)) {
        continue;
      }
      for (size_t k = 0; k < found.size(); ++k) {
        if (k == j || absorbed[k] || track_of[k] < 0) continue;
        const Track& t = tracks[track_of[k]];
        if (!Touch(found[j].mask, found[j].box, found[k].mask, found[k].box,
                   3)) {
          continue;
        }
        const int k_in = OverlapWithHeld(found[k].mask, t.object);
        const bool moved_piece = state[k] == TrackState::kMoved &&
                                 2 * k_in > found[k].area && unchanged(k);
        if (state[k] != TrackState::kKept && !moved_piece) continue;
        // k covers less than 3/4 of the last mask, j and k together at
        // least, and a quarter of j is inside it.
        const int j_in = OverlapWithHeld(found[j].mask, t.object);
        const bool inside = 2 * j_in > found[j].area;
        const bool completes =
            !inside && 4 * k_in < 3 * t.object.area &&
            4 * (j_in + k_in) >= 3 * t.object.area &&
            4 * j_in >= found[j].area &&
            !held_by_another(found[j].mask, found[j].area - j_in, track_of[k]);
        if (!inside && !completes) continue;
        join(j, k);
        if (moved_piece) {
          state[k] = StateOfMotion(world[k] - shift - t.world_centroid);
        }
        break;
      }
    }
  }

  // The tracks some object has now (the two rules below keep it up to date).
  std::vector<bool> matched_track(tracks.size(), false);
  for (size_t j = 0; j < found.size(); ++j) {
    if (track_of[j] >= 0) matched_track[track_of[j]] = true;
  }

  // A joined track seen last frame that matched no object, while objects
  // without a track are its pieces: its parts moved apart, and its
  // centroid, between them, was near neither. Each such part takes its
  // piece's identity: the track's own (the first piece matched of those
  // without a former identity), or the one it had before it was joined.
  for (size_t i = 0; i < tracks.size(); ++i) {
    const Track& t = tracks[i];
    if (matched_track[i] || !t.composite || t.id == 0 || t.pieces.size() < 2 ||
        t.last_seen_frame != frame_index_ - 1) {
      continue;
    }
    std::vector<bool> taken(t.pieces.size(), false);
    bool own_taken = false;
    for (size_t j = 0; j < found.size(); ++j) {
      if (absorbed[j] || track_of[j] >= 0 || split_from[j]) continue;
      const int p = MatchingPiece(pieces[j].front(), shift, t.pieces);
      if (p < 0 || taken[p]) continue;
      const Piece& piece = t.pieces[p];
      if (piece.former_id == 0) {
        if (own_taken) continue;
        own_taken = true;
        track_of[j] = static_cast<int>(i);
        matched_track[i] = true;
        state[j] = StateOfMotion(world[j] - shift - piece.world_centroid);
      } else {
        split_from[j] = piece;
        ++out.split;
      }
      taken[p] = true;
    }
  }

  // Whether track `t`, seen last frame, and track `w` were two pieces of
  // object `k` of this frame: an object moving before a still camera that
  // INC cut in two last frame, one piece appearing beside the other (seen
  // before), and that moved on from where the old piece's mask was. They
  // touched; `k` is about their summed size (within a quarter) and larger
  // than `w` by at least half of `t`; the two together moved by more than
  // moved_m to where `k` is, within the association's gate. Not two
  // objects seen apart before, swept along and cut as one; not with a
  // moving camera (a still object seen anew beside another and cut as one
  // with it the next frame moves in the world as far as a pushed one).
  const auto pieces_of = [&](const Track& t, const Track& w, size_t k) {
    if (!a.still || w.last_seen_frame != frame_index_ - 1 ||
        w.object.mask.empty() || std::min(t.frames_seen, w.frames_seen) != 1 ||
        std::max(t.frames_seen, w.frames_seen) == 1) {
      return false;
    }
    const int sum = t.object.area + w.object.area;
    if (4 * std::abs(found[k].area - sum) > sum ||
        2 * (found[k].area - w.object.area) < t.object.area) {
      return false;
    }
    const Eigen::Vector3f both =
        (static_cast<float>(t.object.area) * t.world_centroid +
         static_cast<float>(w.object.area) * w.world_centroid) /
        static_cast<float>(sum);
    const float moved = (world[k] - shift - both).norm();
    return moved > options_.moved_m &&
           moved < AssociationGate(found[k].extent.maxCoeff()) &&
           HeldTouch(t.object, w.object, found[k].mask.size(), 3);
  };
  // A track seen last frame and matched to nothing, whose last mask is
  // mostly under one object's mask now, or that was with the object's
  // track the two pieces of it (pieces_of: it moved away from its last
  // mask), was a piece of that object: its identity joins the object's
  // (the pieces of an object INC cut in two become one object when it
  // comes whole), or the object's joins its.
  for (size_t i = 0; i < tracks.size(); ++i) {
    Track& t = tracks[i];
    if (matched_track[i] || t.id == 0 ||
        t.last_seen_frame != frame_index_ - 1 || t.object.mask.empty()) {
      continue;
    }
    for (size_t k = 0; k < found.size(); ++k) {
      if (absorbed[k] || track_of[k] < 0) continue;
      Track& whole = tracks[track_of[k]];
      const bool cut_off = pieces_of(t, whole, k);
      if (!cut_off &&
          2 * OverlapWithHeld(found[k].mask, t.object) <= t.object.area) {
        continue;
      }
      // The object goes on under the identity of its larger piece; of the
      // piece seen before when the other was cut off it last frame.
      if (cut_off ? t.frames_seen > whole.frames_seen
                  : t.object.area > whole.object.area) {
        std::swap(t.id, whole.id);
        whole.frames_seen = std::max(whole.frames_seen, t.frames_seen);
      }
      composite[k] = true;
      t.id = 0;  // forgotten below
      ++out.joined;
      break;
    }
  }
}

}  // namespace fovea
