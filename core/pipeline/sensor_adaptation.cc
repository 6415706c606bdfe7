#include "core/pipeline/sensor_adaptation.h"

#include <cmath>

namespace fovea {

void AdaptToSensor(const SensorModel& sensor, SupportPlaneOptions& options) {
  options.sigma0_m = sensor.sigma0_m;
  options.sigma_per_z2 = sensor.sigma_per_z2;
}

void AdaptToSensor(const SensorModel& sensor, TableSceneOptions& options) {
  options.sigma0_m = sensor.sigma0_m;
  options.sigma_per_z2 = sensor.sigma_per_z2;
}

void AdaptToSensor(const SensorModel& sensor, SurfaceModelOptions& options) {
  options.surface_sigma = std::hypot(options.surface_sigma, sensor.sigma0_m);
}

void AdaptToSensor(const SensorModel& sensor, BodyFitOptions& options) {
  options.sigma0_m = sensor.sigma0_m;
  options.sigma_per_z2 = sensor.sigma_per_z2;
}

}  // namespace fovea
