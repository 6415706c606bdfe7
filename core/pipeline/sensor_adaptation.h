#ifndef FOVEA_CORE_PIPELINE_SENSOR_ADAPTATION_H_
#define FOVEA_CORE_PIPELINE_SENSOR_ADAPTATION_H_

#include "core/frame/sensor_model.h"
#include "core/scene/support_plane.h"
#include "core/scene/table_scene.h"
#include "core/segmentation/body_fit.h"
#include "core/segmentation/surface_model.h"

namespace fovea {

// The thresholds of the pipeline that depend on the sensor's depth noise
// come from its SensorModel through these: what is on the support plane
// and what stands above it, a band of 3 sigma(z) (at least the Kinect-tuned
// default). Windows given in pixels already scale with the focal length
// (f / 525 px), and normals and edges are metric.
//
// Planar patches keep their Kinect thresholds with every sensor: loosening
// them to the active-stereo noise merged touching objects' faces, and
// lowered object recall on 40 active-stereo rooms (fovea-eval rooms: INC
// 0.757 to 0.728, COS 0.801 to 0.796), while a patch split by noise is
// joined again by COS's and INC's grouping.
void AdaptToSensor(const SensorModel& sensor, SupportPlaneOptions& options);
void AdaptToSensor(const SensorModel& sensor, TableSceneOptions& options);
// INC's surface models (which neighbouring surfaces one B-spline explains
// better than two) take the sensor's noise floor sigma0_m, in quadrature
// with surface_sigma: a RealSense's millimetre at short range otherwise
// reads as two surfaces where one curved one is (a bowl's inside; on the
// four RealSense frames masks per object 2.07 -> 1.93). Their z^2 term
// stays the Kinect's: with the active-stereo one as well, active-stereo
// rooms lost more (objects above 0.75 F 0.773 -> 0.758) and the RealSense
// frames gained less (2.04). A Kinect v1 model leaves the defaults as they
// are.
void AdaptToSensor(const SensorModel& sensor, SurfaceModelOptions& options);
// INC's body join (one sphere or cylinder through two surfaces) allows the
// sensor's depth noise sigma(z), both terms.
void AdaptToSensor(const SensorModel& sensor, BodyFitOptions& options);

}  // namespace fovea

#endif  // FOVEA_CORE_PIPELINE_SENSOR_ADAPTATION_H_
