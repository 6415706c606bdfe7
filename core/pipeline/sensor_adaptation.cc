#include "core/pipeline/sensor_adaptation.h"

namespace fovea {

void AdaptToSensor(const SensorModel& sensor, SupportPlaneOptions& options) {
  options.sigma0_m = sensor.sigma0_m;
  options.sigma_per_z2 = sensor.sigma_per_z2;
}

void AdaptToSensor(const SensorModel& sensor, TableSceneOptions& options) {
  options.sigma0_m = sensor.sigma0_m;
  options.sigma_per_z2 = sensor.sigma_per_z2;
}

}  // namespace fovea
