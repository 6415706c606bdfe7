#ifndef FOVEA_SERVER_SEGMENT_REACTOR_H_
#define FOVEA_SERVER_SEGMENT_REACTOR_H_

#include <grpcpp/grpcpp.h>

#include <memory>

#include "absl/status/status.h"
#include "fovea/v1/segment.pb.h"
#include "server/perception_service.h"
#include "server/work_queue.h"

namespace fovea::server {

// The reactor of one Segment or SegmentIncremental call (a server stream
// of SegmentResponse), `request` parsed as `parsed` says (ParseUnlessBusy):
// options converted at once, the work on a worker, each message written as
// the worker makes it (segment_reactor.cc). Deletes itself when done.
grpc::ServerWriteReactor<v1::SegmentResponse>* NewSegmentReactor(
    const ServiceConfig& config, WorkQueue& work,
    grpc::CallbackServerContext* context,
    std::unique_ptr<v1::SegmentRequest> request, const absl::Status& parsed);
grpc::ServerWriteReactor<v1::SegmentResponse>* NewSegmentIncrementalReactor(
    const ServiceConfig& config, WorkQueue& work,
    grpc::CallbackServerContext* context,
    std::unique_ptr<v1::SegmentIncrementalRequest> request,
    const absl::Status& parsed);

}  // namespace fovea::server

#endif  // FOVEA_SERVER_SEGMENT_REACTOR_H_
