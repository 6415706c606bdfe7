#include "tests/server/server_fault_fixture.h"

#include "core/synth/synth_scene.h"
#include "server/convert.h"

namespace fovea::server::testing {
namespace {

// A 320 x 240 synthetic table scene: small, so that a whole call is quick.
v1::Frame SmallFrame() {
  synth::SceneSpec spec = synth::RandomSceneSpec(3, {});
  spec.width = 320;
  spec.height = 240;
  spec.intrinsics = {262.5, 262.5, 159.5, 119.5};
  const synth::SynthScene scene =
      synth::RenderScene(spec, synth::NoiseOptions{}, 3);
  return ToProtoFrame(scene.frame.frame, DepthEncoding::k32FC1);
}

}  // namespace

std::string MethodName(Method method) {
  switch (method) {
    case Method::kDetect:
      return "Detect";
    case Method::kSegment:
      return "Segment";
    case Method::kSegmentIncremental:
      break;
  }
  return "SegmentIncremental";
}

const Requests& SmallRequests() {
  static const Requests* const requests = [] {
    auto* made = new Requests;
    const v1::Frame frame = SmallFrame();
    *made->detect.mutable_frame() = frame;
    *made->segment.mutable_frame() = frame;
    made->segment.set_max_objects(kStreamObjects);
    *made->incremental.mutable_frame() = frame;
    made->incremental.set_max_objects(kStreamObjects);
    return made;
  }();
  return *requests;
}

CallResult RunCall(v1::Perception::Stub& stub, Method method,
                   const Requests& requests, grpc::ClientContext& context) {
  switch (method) {
    case Method::kDetect: {
      CallResult result;
      v1::DetectResponse response;
      result.status = stub.Detect(&context, requests.detect, &response);
      return result;
    }
    case Method::kSegment:
      return ReadAll(*stub.Segment(&context, requests.segment));
    case Method::kSegmentIncremental:
      break;
  }
  return ReadAll(*stub.SegmentIncremental(&context, requests.incremental));
}

}  // namespace fovea::server::testing
