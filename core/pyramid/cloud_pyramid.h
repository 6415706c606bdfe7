#ifndef FOVEA_CORE_PYRAMID_CLOUD_PYRAMID_H_
#define FOVEA_CORE_PYRAMID_CLOUD_PYRAMID_H_

#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "core/frame/organized_cloud.h"
#include "core/frame/rgbd_frame.h"

namespace fovea {

// Gaussian pyramid of an organized point cloud (thesis section 2.4,
// eq. 2.19-2.29).
//
// Sizes: level l + 1 keeps rows and columns 0, 2, 4, ... of the filtered
// level l, so it is ceil(w / 2) x ceil(h / 2) (the sizes cv::pyrDown and
// cv::pyrUp use, so colour and maps can move between levels with them).
// Pixel (u, v) of level l sits on pixel (2^l u, 2^l v) of level 0.

struct CloudPyramidOptions {
  // Most levels, level 0 (the input) included (thesis section 2.4: L = 8).
  // [1, 16].
  int max_levels = 8;
  // A level is built only if both its width and its height are at least
  // this many pixels; the pyramid stops at the first level that would be
  // smaller. >= 1. (4 px: the 5-tap kernel still has a centre and two
  // neighbours on each side.)
  int min_size = 4;
};

// OK, or INVALID_ARGUMENT naming the field that breaks its range.
absl::Status Validate(const CloudPyramidOptions& options);

struct CloudPyramid {
  // levels[0] is the input (its cv::Mat headers: it shares the caller's
  // pixels, no copy); levels[l] for l >= 1 own their pixels.
  std::vector<OrganizedCloud> levels;

  int size() const { return static_cast<int>(levels.size()); }
};

// Intrinsics of the level below `intrinsics` ("keep every second pixel").
// The kernel is centred on the kept pixel, so coarse pixel u' is fine pixel
// u = 2 u'. With u = fx X / Z + cx:
//   u' = u / 2 = (fx / 2) X / Z + cx / 2,
// hence fx' = fx / 2, fy' = fy / 2, cx' = cx / 2, cy' = cy / 2.
// ((cx - 0.5) / 2 would be right for 2x2 block averaging, whose coarse
// pixel sits between fine pixels 2u' and 2u' + 1; not what is done here.)
Intrinsics DownsampleIntrinsics(const Intrinsics& intrinsics);

// One pyramid step (eq. 2.19-2.26): each of X, Y, Z, Nx, Ny, Nz is
// filtered with the separable kernel k = [1 4 6 4 1] / 16 over VALID
// pixels only and renormalised by the weight of those pixels:
//   P'(u) = sum_i k_i m(u + i) P(u + i) / sum_i k_i m(u + i)
// with m = 1 where the point (for X, Y, Z) or the normal (for Nx, Ny, Nz)
// exists. Pixels outside the image weigh 0, like missing ones. A pixel
// whose 5x5 window holds no valid pixel stays NaN; missing values are
// never read, so a hole neither spreads NaN nor pulls its neighbours
// towards 0. Then every second row and column is kept. Normals are
// rescaled to unit length (NaN where the filtered normal is shorter than
// kMinNormalLength: opposite normals cancelled). Colour is cv::pyrDown'ed
// (empty colour stays empty). Intrinsics: DownsampleIntrinsics.
// Note: like the thesis, the filter does not stop at depth edges; a
// coarse pixel on an edge averages both surfaces.
// Input: xyz CV_32FC3 (required, non-empty), normals CV_32FC3 of the same
// size or empty (then left empty), colour CV_8UC3 of the same size or empty.
// INVALID_ARGUMENT otherwise.
absl::StatusOr<OrganizedCloud> DownsampleCloud(const OrganizedCloud& cloud);

// Shortest filtered normal that is still rescaled to unit length.
inline constexpr float kMinNormalLength = 1e-3f;

// Level 0 is `cloud`, then DownsampleCloud until `max_levels` levels exist
// or the next level would be smaller than `min_size` in either dimension.
// A cloud smaller than `min_size` still gives its level 0. Errors:
// INVALID_ARGUMENT from Validate or for a malformed cloud (see
// DownsampleCloud); an empty xyz is INVALID_ARGUMENT too.
absl::StatusOr<CloudPyramid> BuildCloudPyramid(
    const OrganizedCloud& cloud, const CloudPyramidOptions& options);

}  // namespace fovea

#endif  // FOVEA_CORE_PYRAMID_CLOUD_PYRAMID_H_
