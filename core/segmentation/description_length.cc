#include "core/segmentation/description_length.h"

#include <algorithm>
#include <cmath>

#include "core/segmentation/surface_model_internal.h"

namespace fovea::surface_model_internal {

double ParameterBits(int points, int parameters,
                     const SurfaceModelOptions& options) {
  return options.kappa_parameter *
         std::log2(static_cast<double>(std::max(points, 2))) * parameters;
}

void AddResidual(const SurfaceModel& model, const Eigen::Vector3f& p,
                 float weight, DataCode& code) {
  if (model.kind == SurfaceKind::kPlane) {
    const Eigen::Vector3f n = model.plane.head<3>();
    code.Add(p, n.dot(p) + model.plane.w(), n, weight);
    return;
  }
  const BSplineSurface& spline = model.spline;
  const Eigen::Vector3f l = spline.axes.transpose() * (p - spline.origin);
  const Eigen::Vector2f extent = spline.max_uv - spline.min_uv;
  const Eigen::Vector2f uv =
      (l.head<2>() - spline.min_uv).cwiseQuotient(extent);
  Eigen::Vector2f gradient;
  const float h = HeightAndGradient(spline, uv.x(), uv.y(), &gradient);
  const Eigen::Vector3f t(-gradient.x() / extent.x(),
                          -gradient.y() / extent.y(), 1.0f);
  const float length = t.norm();
  code.Add(p, (l.z() - h) / length, spline.axes * (t / length), weight);
}

}  // namespace fovea::surface_model_internal
