#ifndef FOVEA_CORE_SYNTH_SYNTH_SCENE_H_
#define FOVEA_CORE_SYNTH_SYNTH_SCENE_H_

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <vector>

#include "absl/status/status.h"
#include "core/frame/osd_pcd.h"
#include "core/frame/rgbd_frame.h"

namespace fovea::synth {

// Synthetic table-top scenes with ground truth, ray-cast through a pinhole
// camera. World frame: the table top is the plane z = 0, +z up, metres.
// Every object rests on the table or on another object.
//
// Determinism: all randomness comes from std::mt19937_64 (bit-exact by the
// standard) through distributions computed in core/synth/random.h, so a seed
// gives the same scene with every standard library (floating-point maths
// such as std::sin may still differ in the last bit between libms).

enum class Shape { kBox, kCylinder, kSphere, kCone, kBowl, kCup };

// Procedural surface textures, in world coordinates (metres), modulating
// the albedo: what makes a floor, a table top or a wall look like one to
// colour operators instead of a flat fill.
enum class Texture {
  kFlat,    // the albedo as is
  kWood,    // grain: stripes along world x, +-12 % brightness, 4-9 mm period
  kCarpet,  // fine speckle, +-25 % brightness per 4 mm cell
  kPaint,   // slow blotches, +-5 % over 20 cm (walls, furniture)
  // Printed packaging or a label: blobs 2-6 cm across of
  // Primitive::print_rgb beside the albedo, covering from none to most of
  // a face (the share wanders over 12 cm), in the primitive's own frame
  // (they move with it).
  kPrint,
};

struct Primitive {
  Shape shape = Shape::kBox;
  // Pose of the primitive's local frame in the world. Local frames:
  //   box:      centred, half sizes `half_extents` along local x, y, z;
  //   cylinder: axis local z, centred, radius `radius`, half height
  //             `half_extents.z()`, with caps;
  //   sphere:   centred, radius `radius`;
  //   cone:     axis local z, base disc (radius `radius`) at local
  //             z = -half_extents.z(), apex at +half_extents.z();
  //   bowl:     a spherical shell `thickness` thick, open at the top: the
  //             outer sphere of radius `radius` is centred at local
  //             z = +half_extents.z() (the rim, at its equator) and cut
  //             flat at z = -half_extents.z() (the foot); its inside is
  //             the sphere through the rim's inner circle (radius -
  //             thickness) whose lowest point, the floor, is
  //             max(thickness, floor_height) above the foot; needs
  //             2 half_extents.z() < radius; with `floor_radius` > 0
  //             the floor is a flat disc of that radius and the inside is
  //             the sphere through the rim's inner circle and the disc's
  //             edge (a real bowl's flat inner bottom);
  //   cup:      a cylindrical shell `thickness` thick with a bottom as
  //             thick, open at the top: axis local z, outer radius
  //             `radius`, half height half_extents.z().
  Eigen::Isometry3f pose = Eigen::Isometry3f::Identity();
  Eigen::Vector3f half_extents = Eigen::Vector3f::Constant(0.05f);
  float radius = 0.05f;
  float thickness = 0.005f;  // bowl and cup walls, metres, < radius
  // Bowl: height of the inner floor above the foot, metres (a real bowl's
  // foot ring and bottom, 1-2 cm); below `thickness` the floor is
  // `thickness` up.
  float floor_height = 0.0f;
  // Bowl: radius of its flat inner floor, metres; 0 (the default) curves
  // the inside down to a single lowest point. At most
  // sqrt((radius - thickness)^2 - depth^2), depth the rim's height above the
  // floor (so the inside widens all the way up), and below the foot's
  // radius sqrt(radius^2 - (2 half_extents.z())^2). Other shapes ignore it.
  float floor_radius = 0.0f;
  Eigen::Vector3f rgb = {0.8f, 0.2f, 0.2f};  // albedo, [0, 1]
  Texture texture = Texture::kFlat;
  // kPrint's second albedo, [0, 1]; other textures ignore it.
  Eigen::Vector3f print_rgb = {1.0f, 1.0f, 1.0f};
};

// Labels of what is not an object on the support table (OSD keeps 1-9
// for the table; rooms use the same range so that ObjectId is 0 for all).
inline constexpr int kSupportTableLabel = 1;  // top and edge of the support
inline constexpr int kFloorLabel = 2;
inline constexpr int kWallLabel = 3;
inline constexpr int kFurnitureLabel = 4;    // legs, chairs, cabinets
inline constexpr int kOtherTableLabel = 5;   // another table's top
inline constexpr int kOtherObjectLabel = 6;  // objects not on the support

// A surface of the room around the table: rendered and labelled, never an
// object of the ground truth.
struct BackgroundPart {
  Primitive primitive;
  int label = kFurnitureLabel;  // one of the labels above, 1..9
};

// A further primitive of an object made of several (a mug's handle, an
// open box's walls): rendered with the label of spec.objects[object], its
// pixels counted in that object's ObjectTruth::visible_pixels.
struct ObjectPart {
  Primitive primitive;
  int object = 0;  // index into SceneSpec::objects
};

struct SceneSpec {
  // Table top: a rectangle of the plane z = 0 centred at the origin.
  Eigen::Vector2f table_half_size = {0.6f, 0.4f};  // metres
  Eigen::Vector3f table_rgb = {0.55f, 0.45f, 0.35f};
  Texture table_texture = Texture::kFlat;
  std::vector<Primitive> objects;
  // The further parts of objects made of several primitives (empty: every
  // object is its one primitive).
  std::vector<ObjectPart> object_parts;
  // The room: floor, walls, furniture, other tables and what stands on
  // them (empty for a bare table-top scene).
  std::vector<BackgroundPart> background;
  // Camera pose in the world (camera frame: x right, y down, z forward).
  Eigen::Isometry3f camera_pose = Eigen::Isometry3f::Identity();
  Intrinsics intrinsics = kKinectV1Intrinsics;
  int width = 640;   // pixels, > 0
  int height = 480;  // pixels, > 0
};

// OK, or INVALID_ARGUMENT naming the field: sizes and focal lengths must be
// positive, radii and half extents positive, albedos in [0, 1], poses
// rotations; object parts name an object of `objects`.
absl::Status Validate(const SceneSpec& spec);

struct NoiseOptions {
  bool enabled = true;
  // Axial noise sigma = sigma0_m + k * z^2 (Khoshelham & Elberink 2012:
  // 1.43e-3 / m, no floor, for the Kinect v1).
  float sigma_per_z2 = 1.43e-3f;
  float sigma0_m = 0.0f;
  // The axial noise is smoothed over this many pixels (Gaussian sigma) and
  // rescaled to keep its sigma: stereo matching windows make neighbouring
  // depths err together. 0 = independent per pixel.
  float noise_correlation_px = 0.0f;
  // Disparity quantisation: depth is quantised to steps of
  // z^2 / (focal_px * baseline_m) * disparity_step (Kinect: 1/8 px,
  // baseline 0.075 m). A step of 0 quantises nothing (time of flight,
  // whose millimetre steps lie below its noise).
  float baseline_m = 0.075f;
  float disparity_step_px = 0.125f;
  // Depth is dropped within this many pixels of a depth jump larger than
  // `edge_jump_m` (the projector shadow and edge dropouts).
  int edge_dropout_px = 2;
  float edge_jump_m = 0.03f;
  // Mixed ("flying") pixels: an edge-dropout pixel (not a shadow's) keeps
  // a depth with this probability, between its own and the nearer
  // surface's (a time-of-flight pixel that sees both averages them); it
  // belongs to no object. 0 = every edge pixel drops.
  float flying_pixel_probability = 0.0f;
  // Shadows: a point hidden from a second viewpoint `shadow_baseline_m` to
  // the camera's right (the projector, or the second imager of a stereo
  // pair) has no depth. This is the band left of every foreground object
  // that both sensors show, f * b * (1 / z_near - 1 / z_far) pixels wide.
  // 0 = off.
  float shadow_baseline_m = 0.0f;
  // With shadows on: the image's left border, which the second viewpoint
  // does not see (f * b / z pixels wide), has no depth either (active
  // stereo; the Kinect's projector covers it).
  bool border_band = false;
  // Surfaces darker than this albedo lose their depth with probability
  // `dark_dropout_probability` per pixel.
  float dark_albedo = 0.12f;
  float dark_dropout_probability = 0.6f;
  // Colour noise, standard deviation in 8-bit units.
  float color_sigma = 3.0f;
};

// OK, or INVALID_ARGUMENT naming the field (negative sigmas, non-positive
// baseline or disparity step, probabilities outside [0, 1]).
absl::Status Validate(const NoiseOptions& options);

// The two sensors rooms are rendered with, each measured against the
// sensor's real frames (`fovea-eval realism`, docs/realism.md). Kinect v1:
// the defaults above with its projector's shadow (7.5 cm baseline) and the
// noise correlated over 2 px (the structured light's correlation window:
// uncorrelated, the table's normals spread 1.0 degree against OSD's 2.8;
// now 3.2). Active stereo (RealSense D4xx-like): sigma 0.5 mm + 1.25e-3 z^2
// correlated over 3 px (the four RealSense frames: 0.36-0.48 mm about an
// 8 px cell's plane at 0.4-1.4 m and normals spread 4.7 degrees; 1 mm +
// 2.5e-3 z^2 over 1.5 px gave 0.8-1.8 mm and 7.5 degrees), sub-pixel
// disparity steps of 1/20 px over a 5 cm baseline, shadows and the left
// border band, dark surfaces losing depth more often.
NoiseOptions KinectV1Noise();
NoiseOptions ActiveStereoNoise();
// Time of flight (Azure Kinect / Kinect v2-like), from published
// characterisations, as no frames of one are at hand to measure against:
// sigma 1 mm + 0.5e-3 z^2 per pixel (Fankhauser et al. 2015, Tolgyessy et
// al. 2021), no disparity steps, no shadows (illuminator beside the
// sensor), a pixel of mixed depths or none along depth edges, dark
// surfaces (little returned infrared) losing depth.
NoiseOptions TimeOfFlightNoise();

// KinectV1Noise() with independent per-pixel noise (noise_correlation_px
// 0), as every synthetic Kinect scene was rendered before docs/realism.md
// measured them. The frame-stream sequences (sequence.h) keep it, so that
// the tracking figures and tests stay comparable until streams are
// measured against real ones; so do the unit tests' training piles.
NoiseOptions IndependentKinectV1Noise();

// Ground truth of one object as rendered.
struct ObjectTruth {
  int label = 0;        // OSD-style label 10 * (index + 2), object id index + 2
  Primitive primitive;  // spec.objects[index]; its parts are not repeated
  // Pixels carrying `label` in the rendered frame, over all the object's
  // parts: seen by the camera, with depth or dropped for being dark (an
  // edge dropout's pixels have label 0).
  int visible_pixels = 0;
};

struct SynthScene {
  LabelledFrame frame;  // labels: 0 no data, 1 table, 20, 30, ... objects
  std::vector<ObjectTruth> objects;
  // The table plane in the camera frame, n . p + d = 0, n towards the
  // camera.
  Eigen::Vector3f table_normal_camera = Eigen::Vector3f::UnitZ();
  float table_d_camera = 0.0f;
};

// Renders `spec` (noise from `seed`) by casting one ray per pixel centre;
// the nearest surface wins. On return:
//   frame.frame.depth: camera z in metres, NaN where the ray hits nothing or
//                      the noise model dropped the depth;
//   frame.frame.color: albedo times (ambient + Lambertian term of a fixed
//                      world-frame light), RGB; pixels seeing nothing show a
//                      flat grey background;
//   frame.labels:      0 where the ray hits nothing or an edge dropout
//                      removed the depth (a dark surface's dropped pixels
//                      keep their label: its object is there), 1 table,
//                      10 * (k + 2) for
//                      spec.objects[k] and the object_parts of object k,
//                      each background part's label;
//   frame.name:        "synth-<seed>"; frame.frame.intrinsics =
//                      spec.intrinsics.
// With noise.enabled the depth gets, in this order, edge dropouts (computed
// on the noise-free depth), dark-surface dropouts, axial Gaussian noise and
// disparity quantisation, and the colour gets Gaussian noise. Shadows
// (shadow_baseline_m) are computed on the noise-free depth too.
// Precondition (checked): Validate(spec) and Validate(noise) are OK.
SynthScene RenderScene(const SceneSpec& spec, const NoiseOptions& noise,
                       uint64_t seed);

struct RandomSceneOptions {
  int min_objects = 2;
  int max_objects = 6;
  // Probabilities that an object is stacked on a box already placed, or
  // placed touching another object.
  float stack_probability = 0.2f;
  float touch_probability = 0.3f;
  // Probability that an object is placed between the camera and an object
  // already on the table, partly hiding it.
  float occlude_probability = 0.15f;
  // Probability that an object has a dark albedo (loses depth under the
  // default NoiseOptions).
  float dark_object_probability = 0.1f;
  // The household mix instead of geometric primitives: boxes, books lying
  // flat, cylinders, bowls and cups with real cavities, a few spheres and
  // cones.
  bool household = false;
  // Probability that an object is a box leaning over towards one on the
  // table (stack + touch + occlude + lean <= 1).
  float lean_probability = 0.0f;
  // Free objects go within this share of the work area around the look-at
  // point (smaller: a pile), (0, 1].
  float work_area_scale = 1.0f;
  // Camera: height above the table and distance back from its centre,
  // metres, looking at the table centre (a Kinect on a robot's head).
  float camera_height = 0.75f;
  float camera_distance = 0.75f;
  // Uniform jitter of the eye (x, y, z) and of the look-at target (x, y),
  // +- metres.
  float camera_jitter = 0.04f;
  // Every object keeps at least this share of the pixels it would cover
  // alone (checked on a half-resolution render while placing), so that no
  // object is hidden entirely. [0, 1].
  float min_visible_fraction = 0.3f;
};

// OK, or INVALID_ARGUMENT naming the field: 0 <= min_objects <= max_objects
// <= 20, probabilities in [0, 1] with stack + touch + occlude <= 1, camera
// height > 0, camera distance >= 0, jitter >= 0.
absl::Status Validate(const RandomSceneOptions& options);

// A random table-top scene: boxes, cylinders, spheres and cones at random
// poses and colours (3-15 cm), some touching, stacked and occluding, all on
// the table and in view of the default 640 x 480 Kinect camera. Boxes rest
// on a face, cylinders stand or lie, spheres and cones stand on the table;
// stacked objects stand on a box. Vertical projections of objects at
// overlapping heights do not overlap, so nothing interpenetrates. The
// number of objects is drawn from [min_objects, max_objects]; on a crowded
// table fewer may fit. Deterministic: the same seed gives the same spec.
// Precondition (checked): Validate(options) is OK.
SceneSpec RandomSceneSpec(uint64_t seed, const RandomSceneOptions& options);

// RandomSceneSpec's objects added to `spec` as it is (its table, camera,
// resolution and intrinsics), free ones within the work area around
// `target` (world x, y on the table). The room's background parts do not
// take part in the visibility checks. Deterministic in `seed`.
// Precondition (checked): Validate(options) is OK.
void PlaceRandomObjects(uint64_t seed, const RandomSceneOptions& options,
                        const Eigen::Vector2f& target, SceneSpec& spec);

// The camera pose (camera to world) looking at `target` from `eye` with the
// world +z up: camera z along target - eye, camera x horizontal, camera y
// pointing down in the world. Looking straight down (or up), image up is
// world +y. `eye` must differ from `target`.
Eigen::Isometry3f LookAt(const Eigen::Vector3f& eye,
                         const Eigen::Vector3f& target);

// The demo scene: RandomSceneSpec(seed, {}) rendered with default noise and
// `seed`. Seeds 1..20 give 2-6 visible objects.
SynthScene GenerateScene(uint64_t seed);

// Dense clutter: 8-16 household objects (boxes, books lying flat,
// cylinders, bowls and cups with cavities, a few spheres and cones) in a
// compact pile, a quarter stacked, 40 % touching, some occluding or
// leaning, seen by a Kinect from 0.7 m up and 0.65 m back.
RandomSceneOptions PileOptions();

// RandomSceneSpec(seed, PileOptions()) rendered with KinectV1Noise();
// frame.name "pile-<seed>". Crowded piles may hold fewer objects than
// drawn: every object keeps 30 % of its pixels.
SynthScene GeneratePile(uint64_t seed);

}  // namespace fovea::synth

#endif  // FOVEA_CORE_SYNTH_SYNTH_SCENE_H_
