#ifndef FOVEA_CORE_SALIENCY_SYM3D_H_
#define FOVEA_CORE_SALIENCY_SYM3D_H_

#include <opencv2/core.hpp>

#include "absl/status/statusor.h"
#include "core/frame/organized_cloud.h"
#include "core/scene/table_scene.h"

namespace fovea {

struct Sym3dOptions {
  // Side of the square kernel, pixels of the level it runs on, odd, >= 3
  // (thesis section 2.3.4: a k x k kernel around each point).
  int kernel_size = 7;
  // A neighbour belongs to the patch when it is within this many times the
  // kernel's metric half-width (half_k * z / fx) of the centre point in 3D;
  // keeps the background out of patches on silhouettes.
  float max_distance_factor = 2.0f;
  // A side of a candidate plane needs at least this many points.
  int min_side_points = 3;
  // Points within this fraction of the kernel's metric half-width of a
  // candidate plane lie on it and belong to neither side.
  float plane_band_fraction = 0.1f;
  // w2 (eq. 2.16): the angle between the two sides' mean normals at which a
  // patch counts as fully curved, degrees. A flat patch (angle 0) scores 0.
  float curved_angle_deg = 30.0f;
};

absl::Status Validate(const Sym3dOptions& options);

// 3D symmetry saliency on partial views (thesis section 2.3.4,
// eq. 2.8-2.18; Potapova, Zillich & Vincze, ACCV 2012). For every candidate
// pixel p of `scene` (a point on the table, see TableScene):
//   1. the patch is the valid points q_i (normals m_i) of the k x k window
//      around p within the distance bound;
//   2. the principal axes e_1..e_3 of the patch's extended Gaussian image
//      (PCA of the normals m_i) are the normals of three candidate planes
//      through p;
//   3. each plane splits the patch by the sign of e_j . (q_i - p) into sides
//      + and -, with mean points P+, P- and unit mean normals M+, M-;
//   4. with R_j the reflection in the plane,
//        dD = |R_j(P+) - P-| / r   (r: mean |q_i - p|, so dD is unitless),
//        dd = |R_j(M+) - M-|,
//        w1 = min(n+, n-) / max(n+, n-)                (eq. 2.14),
//        w2 = min(1, angle(M+, M-) / curved_angle)     (eq. 2.16),
//      Omega_j = exp(-dD) exp(-dd) w1 w2, and Omega_j = 0 when the patch is
//      concave across the plane, (M+ - M-) . e_j <= 0 (eq. 2.18: on a convex
//      surface the normals diverge away from the plane);
//   5. S(p) = max_j Omega_j.
// 0 where there is no depth or no normal and off the candidates; the map is
// linearly normalised. The map has the size of `cloud` (any level of a
// pyramid). A flat patch scores 0 (w2); a patch centred on the symmetry
// line of a cylinder, cone or sphere, or on a box edge, scores high.
absl::StatusOr<cv::Mat> ComputeSym3dSaliency(const OrganizedCloud& cloud,
                                             const TableScene& scene,
                                             const Sym3dOptions& options);

}  // namespace fovea

#endif  // FOVEA_CORE_SALIENCY_SYM3D_H_
