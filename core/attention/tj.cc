#include "core/attention/tj.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "core/base/check.h"
#include "core/base/status_macros.h"

namespace fovea {
namespace {

// A junction has at least this many skeleton branches (crossing number).
constexpr int kJunctionMinBranches = 3;

// Flags per padded pixel.
constexpr uint8_t kVisited = 1;   // labelled into a component
constexpr uint8_t kInBorder = 2;  // on the thinning's candidate list

// The image padded by one background pixel on every side, so that every
// pixel of the image has eight neighbours in the buffers. Pixel (u, v) of
// the image is at index (v + 1) * stride + u + 1; row-major order of
// indices is row-major order of pixels.
struct Grid {
  int width = 0, height = 0, stride = 0;
  std::vector<uint8_t> on;     // 1 = foreground / skeleton
  std::vector<uint8_t> flags;  // kVisited | kInBorder
  // The CV_32FC1 saliency map, not owned; null when thinning a mask.
  const cv::Mat* map = nullptr;
  // Offsets of the neighbours in ring order: N, NE, E, SE, S, SW, W, NW
  // (Guo & Hall's p2 ... p9).
  std::array<int, 8> ring{};

  Grid(int w, int h) : width(w), height(h), stride(w + 2) {
    const size_t n = static_cast<size_t>(w + 2) * (h + 2);
    on.assign(n, 0);
    flags.assign(n, 0);
    ring = {-stride, -stride + 1, 1,  stride + 1,
            stride,  stride - 1,  -1, -stride - 1};
  }
  int Index(int u, int v) const { return (v + 1) * stride + u + 1; }
  int U(int p) const { return p % stride - 1; }
  int V(int p) const { return p / stride - 1; }
  float Saliency(int p) const { return map->ptr<float>(V(p))[U(p)]; }
};

struct Component {
  std::vector<int> pixels;    // padded indices; pixels[0] first in row-major
  double sum = 0.0;           // sum of saliency
  double su = 0.0, sv = 0.0;  // saliency-weighted sums of u and v
  double au = 0.0, av = 0.0;  // sums of u and v
  double Mean() const { return sum / static_cast<double>(pixels.size()); }
};

// 0 -> 1 transitions going once round the ring of neighbour values.
int CrossingNumber(const std::array<uint8_t, 8>& n) {
  int transitions = 0;
  for (int k = 0; k < 8; ++k) transitions += !n[k] && n[(k + 1) % 8];
  return transitions;
}

std::array<uint8_t, 8> RingValues(const Grid& grid, int p) {
  std::array<uint8_t, 8> n;
  for (int k = 0; k < 8; ++k) n[k] = grid.on[p + grid.ring[k]];
  return n;
}

// 8-connected components of grid.on, in row-major order of their first
// pixel; one pass over the image plus the components' pixels.
std::vector<Component> LabelComponents(Grid& grid) {
  std::vector<Component> components;
  std::vector<int> stack;
  for (int v = 0; v < grid.height; ++v) {
    for (int p = grid.Index(0, v), end = p + grid.width; p < end; ++p) {
      if (!grid.on[p] || (grid.flags[p] & kVisited)) continue;
      Component c;
      stack.assign(1, p);
      grid.flags[p] |= kVisited;
      while (!stack.empty()) {
        const int q = stack.back();
        stack.pop_back();
        c.pixels.push_back(q);
        if (grid.map != nullptr) {
          const double s = grid.Saliency(q);
          c.sum += s;
          c.su += s * grid.U(q);
          c.sv += s * grid.V(q);
          c.au += grid.U(q);
          c.av += grid.V(q);
        }
        for (int offset : grid.ring) {
          const int r = q + offset;
          if (grid.on[r] && !(grid.flags[r] & kVisited)) {
            grid.flags[r] |= kVisited;
            stack.push_back(r);
          }
        }
      }
      // The scan met p first; keep it first (the rest is in fill order).
      components.push_back(std::move(c));
    }
  }
  return components;
}

// Guo & Hall 1989, algorithm A1: may pixel p be deleted in subiteration
// `odd` (0 or 1)? C(p) = 1 keeps connectivity, 2 <= N(p) <= 3 keeps line
// ends, and the last term alternates between the south-east and the
// north-west boundary.
bool GuoHallDeletable(const Grid& grid, int p, int odd) {
  const std::array<uint8_t, 8> n = RingValues(grid, p);
  const int p2 = n[0], p3 = n[1], p4 = n[2], p5 = n[3], p6 = n[4], p7 = n[5],
            p8 = n[6], p9 = n[7];
  // Values are 0 or 1, so 1 - x is "not x".
  const int c = ((1 - p2) & (p3 | p4)) + ((1 - p4) & (p5 | p6)) +
                ((1 - p6) & (p7 | p8)) + ((1 - p8) & (p9 | p2));
  const int n1 = (p9 | p2) + (p3 | p4) + (p5 | p6) + (p7 | p8);
  const int n2 = (p2 | p3) + (p4 | p5) + (p6 | p7) + (p8 | p9);
  const int nn = std::min(n1, n2);
  const int m =
      odd == 0 ? ((p6 | p7 | (1 - p9)) & p8) : ((p2 | p3 | (1 - p5)) & p4);
  return c == 1 && nn >= 2 && nn <= 3 && m == 0;
}

// Thins one component in place. Only pixels with a background 4-neighbour
// can be deleted (C(p) = 0 otherwise), so each subiteration examines just
// the border list, which grows by the pixels that deletions expose: the
// total work is bounded by the component's area times a small factor,
// never by the image's.
void ThinComponent(const Component& component, Grid& grid,
                   std::vector<int>& border, std::vector<int>& doomed) {
  const std::array<int, 4> four = {grid.ring[0], grid.ring[2], grid.ring[4],
                                   grid.ring[6]};
  border.clear();
  for (int p : component.pixels) {
    for (int offset : four) {
      if (!grid.on[p + offset]) {
        grid.flags[p] |= kInBorder;
        border.push_back(p);
        break;
      }
    }
  }
  int quiet = 0;  // subiterations in a row that deleted nothing
  for (int odd = 0; quiet < 2; odd ^= 1) {
    doomed.clear();
    for (int p : border) {
      if (GuoHallDeletable(grid, p, odd)) doomed.push_back(p);
    }
    quiet = doomed.empty() ? quiet + 1 : 0;
    for (int p : doomed) grid.on[p] = 0;
    // Drop deleted pixels from the border; add the ones they expose.
    size_t kept = 0;
    for (int p : border) {
      if (grid.on[p]) {
        border[kept++] = p;
      } else {
        grid.flags[p] &= ~kInBorder;
      }
    }
    border.resize(kept);
    for (int p : doomed) {
      for (int offset : four) {
        const int q = p + offset;
        if (grid.on[q] && !(grid.flags[q] & kInBorder)) {
          grid.flags[q] |= kInBorder;
          border.push_back(q);
        }
      }
    }
  }
  for (int p : border) grid.flags[p] &= ~kInBorder;
}

// Yokoi's 8-connectivity number of a pixel from its ring (N, NE, ..., NW):
// sum over the 4-neighbours k of x'_k - x'_k x'_{k+1} x'_{k+2}, x' = 1 - x.
// A pixel with connectivity number 1 is simple: deleting it changes
// neither the 8-connected components of the foreground nor the 4-connected
// components of the background (no branch cut, no hole opened or made).
int ConnectivityNumber(const std::array<uint8_t, 8>& n) {
  int number = 0;
  for (int k = 0; k < 8; k += 2) {
    const int a = 1 - n[k], b = 1 - n[(k + 1) % 8], c = 1 - n[(k + 2) % 8];
    number += a - a * b * c;
  }
  return number;
}

// A staircase corner: 4-neighbours at ring positions k and k + 2 set, the
// opposite ones (k + 4, k + 6) and the diagonal between those (k + 5)
// clear; redundant in 8-connectivity.
bool IsStaircaseCorner(const std::array<uint8_t, 8>& n) {
  for (int k = 0; k < 8; k += 2) {
    if (n[k] && n[(k + 2) % 8] && !n[(k + 4) % 8] && !n[(k + 6) % 8] &&
        !n[(k + 5) % 8]) {
      return true;
    }
  }
  return false;
}

// Is the pixel one of a 2 x 2 block of set pixels?
bool InTwoByTwoBlock(const std::array<uint8_t, 8>& n) {
  for (int k = 0; k < 8; k += 2) {
    if (n[k] && n[k + 1] && n[(k + 2) % 8]) return true;
  }
  return false;
}

// Removes the pixels that keep the thinned component from being one pixel
// wide: simple pixels (see ConnectivityNumber) that are staircase corners
// or part of a 2 x 2 block. Sequential (each test sees the previous
// deletions), in row-major order, repeated until nothing changes; each
// pass but the last deletes a pixel, so the work is bounded by the
// skeleton's size squared at worst and is linear in practice. Returns the
// component's skeleton pixels in row-major order.
std::vector<int> FinishSkeleton(const Component& component, Grid& grid) {
  std::vector<int> skeleton;
  for (int p : component.pixels) {
    if (grid.on[p]) skeleton.push_back(p);
  }
  std::sort(skeleton.begin(), skeleton.end());
  for (bool changed = true; changed;) {
    changed = false;
    size_t kept = 0;
    for (int p : skeleton) {
      const std::array<uint8_t, 8> n = RingValues(grid, p);
      if ((IsStaircaseCorner(n) || InTwoByTwoBlock(n)) &&
          ConnectivityNumber(n) == 1) {
        grid.on[p] = 0;
        changed = true;
      } else {
        skeleton[kept++] = p;
      }
    }
    skeleton.resize(kept);
  }
  // Guo-Hall never removes a component whole, and a simple pixel in a
  // corner or a block has set neighbours that stay.
  FOVEA_CHECK(!skeleton.empty());
  return skeleton;
}

// The junction of `skeleton` nearest the component's centroid (`central`)
// or the most salient one (ties: nearest the saliency-weighted centroid),
// then the first in row-major order; -1 without a junction.
int BestJunction(const std::vector<int>& skeleton, const Component& component,
                 const Grid& grid, bool central) {
  const double n = static_cast<double>(component.pixels.size());
  const double cu = central ? component.au / n : component.su / component.sum;
  const double cv = central ? component.av / n : component.sv / component.sum;
  int best = -1;
  float best_saliency = 0.0f;
  double best_d2 = 0.0;
  for (int p : skeleton) {
    if (CrossingNumber(RingValues(grid, p)) < kJunctionMinBranches) continue;
    const float s = grid.Saliency(p);
    const double du = grid.U(p) - cu, dv = grid.V(p) - cv;
    const double d2 = du * du + dv * dv;
    if (central) {
      if (best < 0 || d2 < best_d2) {
        best = p;
        best_d2 = d2;
      }
      continue;
    }
    if (best < 0 || s > best_saliency || (s == best_saliency && d2 < best_d2)) {
      best = p;
      best_saliency = s;
      best_d2 = d2;
    }
  }
  return best;
}

// Breadth-first search over the skeleton (8-connected steps) from local
// index `source`; fills `parent` and returns the last pixel reached (one of
// the farthest).
int FarthestFrom(int source, const std::vector<int>& skeleton,
                 const std::vector<int>& local, const Grid& grid,
                 std::vector<int>& parent, std::vector<int>& queue) {
  parent.assign(skeleton.size(), -1);
  parent[source] = source;
  queue.assign(1, source);
  for (size_t head = 0; head < queue.size(); ++head) {
    const int i = queue[head];
    for (int offset : grid.ring) {
      const int q = skeleton[i] + offset;
      if (!grid.on[q]) continue;
      const int j = local[q];
      if (parent[j] >= 0) continue;
      parent[j] = i;
      queue.push_back(j);
    }
  }
  return queue.back();
}

// The middle of the skeleton's longest path (see ExtractTjPoints). `local`
// is a scratch buffer of the grid's size holding -1; it is restored.
int MiddleOfLongestPath(const std::vector<int>& skeleton, const Grid& grid,
                        std::vector<int>& local) {
  if (skeleton.size() == 1) return skeleton[0];
  for (size_t i = 0; i < skeleton.size(); ++i) {
    local[skeleton[i]] = static_cast<int>(i);
  }
  std::vector<int> parent, queue;
  const int a = FarthestFrom(0, skeleton, local, grid, parent, queue);
  const int b = FarthestFrom(a, skeleton, local, grid, parent, queue);
  for (int p : skeleton) local[p] = -1;
  // The path from b back to a, with Euclidean arc length from b.
  std::vector<int> path(1, b);
  std::vector<double> length(1, 0.0);
  for (int i = b; i != a; i = parent[i]) {
    const int step = std::abs(skeleton[parent[i]] - skeleton[i]);
    const bool straight = step == 1 || step == grid.stride;
    path.push_back(parent[i]);
    length.push_back(length.back() + (straight ? 1.0 : std::sqrt(2.0)));
  }
  const double half = length.back() / 2.0;
  size_t best = 0;
  for (size_t k = 1; k < path.size(); ++k) {
    if (std::abs(length[k] - half) < std::abs(length[best] - half)) best = k;
  }
  return skeleton[path[best]];
}

}  // namespace

absl::Status Validate(const TjOptions& options) {
  if (!(options.support_fraction >= 0.0f && options.support_fraction < 1.0f)) {
    return absl::InvalidArgumentError(
        absl::StrCat("tj.support_fraction must be in [0, 1), got ",
                     options.support_fraction));
  }
  if (options.min_component_pixels < 0) {
    return absl::InvalidArgumentError(
        absl::StrCat("tj.min_component_pixels must be >= 0, got ",
                     options.min_component_pixels));
  }
  if (!(options.min_mean_fraction >= 0.0f &&
        options.min_mean_fraction <= 1.0f)) {
    return absl::InvalidArgumentError(
        absl::StrCat("tj.min_mean_fraction must be in [0, 1], got ",
                     options.min_mean_fraction));
  }
  return absl::OkStatus();
}

absl::StatusOr<std::vector<AttentionPoint>> ExtractTjPoints(
    const cv::Mat& map, int max_points, const TjOptions& options) {
  FOVEA_RETURN_IF_ERROR(Validate(options));
  if (map.empty() || map.type() != CV_32FC1) {
    return absl::InvalidArgumentError("tj: map must be a non-empty CV_32FC1");
  }
  if (max_points < 0) {
    return absl::InvalidArgumentError(
        absl::StrCat("tj: max_points must be >= 0, got ", max_points));
  }
  std::vector<AttentionPoint> points;
  if (max_points == 0) return points;
  Grid grid(map.cols, map.rows);
  grid.map = &map;
  float global_max = 0.0f;
  for (int v = 0; v < map.rows; ++v) {
    const float* row = map.ptr<float>(v);
    const int p0 = grid.Index(0, v);
    for (int u = 0; u < map.cols; ++u) {
      const bool foreground = row[u] > 0.0f;  // false for NaN
      grid.on[p0 + u] = foreground;
      if (foreground && row[u] > global_max) global_max = row[u];
    }
  }
  if (!(global_max > 0.0f) || !std::isfinite(global_max)) {
    if (global_max > 0.0f) {
      return absl::InvalidArgumentError("tj: map has an infinite value");
    }
    return points;
  }
  if (options.support_fraction > 0.0f) {
    const float support = options.support_fraction * global_max;
    for (int v = 0; v < map.rows; ++v) {
      const float* row = map.ptr<float>(v);
      const int p0 = grid.Index(0, v);
      for (int u = 0; u < map.cols; ++u) {
        if (row[u] < support) grid.on[p0 + u] = 0;
      }
    }
  }
  std::vector<Component> components = LabelComponents(grid);
  const double theta =
      static_cast<double>(options.min_mean_fraction) * global_max;
  std::vector<const Component*> kept;
  for (const Component& c : components) {
    if (c.Mean() >= theta &&
        static_cast<int>(c.pixels.size()) >= options.min_component_pixels) {
      kept.push_back(&c);
    }
  }
  // Rank first, so that only the components that can yield a point are
  // thinned.
  if (options.ranking == TjRanking::kTotalSaliency) {
    std::stable_sort(
        kept.begin(), kept.end(),
        [](const Component* a, const Component* b) { return a->sum > b->sum; });
  } else {
    std::stable_sort(kept.begin(), kept.end(),
                     [](const Component* a, const Component* b) {
                       return a->Mean() > b->Mean();
                     });
  }
  if (static_cast<int>(kept.size()) > max_points) kept.resize(max_points);
  // With kTotalSaliency a point's saliency is its component's total over
  // the largest kept component's area: in [0, 1], non-increasing in rank,
  // and the mean for the largest component.
  size_t largest_area = 1;
  for (const Component* c : kept) {
    largest_area = std::max(largest_area, c->pixels.size());
  }
  std::vector<int> border, doomed, local;
  for (const Component* c : kept) {
    ThinComponent(*c, grid, border, doomed);
    const std::vector<int> skeleton = FinishSkeleton(*c, grid);
    int p = BestJunction(skeleton, *c, grid,
                         options.junction == TjJunction::kCentral);
    if (p < 0) {
      if (local.empty()) local.assign(grid.on.size(), -1);
      p = MiddleOfLongestPath(skeleton, grid, local);
    }
    AttentionPoint point;
    point.u = grid.U(p);
    point.v = grid.V(p);
    point.saliency =
        static_cast<float>(options.ranking == TjRanking::kTotalSaliency
                               ? c->sum / static_cast<double>(largest_area)
                               : c->Mean());
    points.push_back(point);
  }
  return points;
}

absl::StatusOr<cv::Mat> ThinToSkeleton(const cv::Mat& mask) {
  if (mask.empty() || mask.type() != CV_8UC1) {
    return absl::InvalidArgumentError(
        "tj: skeleton mask must be a non-empty CV_8UC1");
  }
  Grid grid(mask.cols, mask.rows);
  for (int v = 0; v < mask.rows; ++v) {
    const uint8_t* row = mask.ptr<uint8_t>(v);
    const int p0 = grid.Index(0, v);
    for (int u = 0; u < mask.cols; ++u) grid.on[p0 + u] = row[u] != 0;
  }
  std::vector<int> border, doomed;
  for (const Component& c : LabelComponents(grid)) {
    ThinComponent(c, grid, border, doomed);
    FinishSkeleton(c, grid);
  }
  cv::Mat skeleton(mask.size(), CV_8UC1);
  for (int v = 0; v < mask.rows; ++v) {
    uint8_t* row = skeleton.ptr<uint8_t>(v);
    const int p0 = grid.Index(0, v);
    for (int u = 0; u < mask.cols; ++u) row[u] = grid.on[p0 + u] ? 255 : 0;
  }
  return skeleton;
}

int SkeletonBranchCount(const cv::Mat& skeleton, int u, int v) {
  if (skeleton.empty() || skeleton.type() != CV_8UC1 || u < 0 || v < 0 ||
      u >= skeleton.cols || v >= skeleton.rows) {
    return 0;
  }
  constexpr std::array<int, 8> kDu = {0, 1, 1, 1, 0, -1, -1, -1};
  constexpr std::array<int, 8> kDv = {-1, -1, 0, 1, 1, 1, 0, -1};
  std::array<uint8_t, 8> n;
  for (int k = 0; k < 8; ++k) {
    const int nu = u + kDu[k], nv = v + kDv[k];
    n[k] = nu >= 0 && nv >= 0 && nu < skeleton.cols && nv < skeleton.rows &&
           skeleton.at<uint8_t>(nv, nu) != 0;
  }
  return CrossingNumber(n);
}

}  // namespace fovea
