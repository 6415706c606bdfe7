#ifndef FOVEA_CORE_PIPELINE_SENSOR_ADAPTATION_H_
#define FOVEA_CORE_PIPELINE_SENSOR_ADAPTATION_H_

#include "core/frame/sensor_model.h"
#include "core/frame/support_plane.h"
#include "core/frame/table_scene.h"

namespace fovea {

// The thresholds of the pipeline that depend on the sensor's depth noise
// come from its SensorModel through these: what is on the support plane
// and what stands above it, a band of 3 sigma(z) (at least the Kinect-tuned
// default). Windows given in pixels already scale with the focal length
// (f / 525 px), and normals and edges are metric.
//
// Planar patches and surface models keep their Kinect thresholds with
// every sensor: loosening them to the active-stereo noise merged touching
// objects' faces, and lowered object recall on 40 active-stereo rooms
// (fovea-eval rooms: INC 0.757 to 0.728, COS 0.801 to 0.796), while a
// patch split by noise is joined again by COS's and INC's grouping.
void AdaptToSensor(const SensorModel& sensor, SupportPlaneOptions& options);
void AdaptToSensor(const SensorModel& sensor, TableSceneOptions& options);

}  // namespace fovea

#endif  // FOVEA_CORE_PIPELINE_SENSOR_ADAPTATION_H_
