#ifndef FOVEA_SERVER_CONVERT_INTERNAL_H_
#define FOVEA_SERVER_CONVERT_INTERNAL_H_

#include <Eigen/Core>

#include "fovea/v1/detect.pb.h"

// Helpers shared by the convert_*.cc files (convert.h is the public
// header); not for other callers.
namespace fovea::server::convert_internal {

// A camera-frame point, metres, as the wire states it.
inline v1::Point3 ToPoint3(const Eigen::Vector3f& p) {
  v1::Point3 out;
  out.set_x(p.x());
  out.set_y(p.y());
  out.set_z(p.z());
  return out;
}

}  // namespace fovea::server::convert_internal

#endif  // FOVEA_SERVER_CONVERT_INTERNAL_H_
