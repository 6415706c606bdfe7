"""scripts/tsan-reports on hand-made ThreadSanitizer logs: a race in
fovea's code is reported (exit 1) even when the racing access is reached
through std:: templates, generated protobuf code or gRPC's callback
threads; races inside gRPC's own inline templates and uninstrumented
libraries are only counted (exit 0)."""

import subprocess
import sys
import tempfile
import unittest
from pathlib import Path

SCRIPT = Path(__file__).resolve().parents[2] / "scripts" / "tsan-reports"
SRC = "/src/fovea"

# Our worker writes a field that a gRPC callback thread reads: fovea's.
OURS_UNDER_GRPC = f"""==================
WARNING: ThreadSanitizer: data race (pid=11)
  Write of size 4 at 0x7b0400000010 by thread T3:
    #0 fovea::server::Job::Finish() {SRC}/server/job.cc:40 (server+0x100)
    #1 std::_Function_handler<void ()>::_M_invoke(std::_Any_data const&) /usr/include/c++/12/bits/std_function.h:290 (server+0x200)

  Previous read of size 4 at 0x7b0400000010 by thread T5:
    #0 std::function<void ()>::operator()() const /usr/include/c++/12/bits/std_function.h:591 (server+0x300)
    #1 fovea::server::Reactor::OnWriteDone(bool) {SRC}/server/reactor.cc:77 (server+0x400)
    #2 grpc::internal::CallbackWithSuccessTag::Run(bool) /usr/include/grpcpp/support/callback_common.h:208 (server+0x500)
    #3 <null> <null> (libgrpc++.so.1.51+0x897ba)

  Thread T3 (tid=3, running) created by main thread at:
    #0 pthread_create ../../../../src/libsanitizer/tsan/tsan_interceptors_posix.cpp:1001 (libtsan.so.2+0x5e686)
    #1 fovea::server::WorkQueue::WorkQueue(int, int) {SRC}/server/work_queue.cc:35 (server+0x600)

SUMMARY: ThreadSanitizer: data race {SRC}/server/job.cc:40 in fovea::server::Job::Finish()
==================
"""

# A generated accessor at the top, our handler below it: fovea's.
OURS_THROUGH_GENERATED_CODE = f"""==================
WARNING: ThreadSanitizer: data race (pid=12)
  Read of size 4 at 0x7b0400000020 by thread T4:
    #0 fovea::v1::Frame::width() const {SRC}/build-tsan/proto/fovea/v1/frame.pb.h:900 (server+0x10)
    #1 fovea::server::HandleDetect() {SRC}/server/handle_detect.cc:20 (server+0x20)

  Previous write of size 4 at 0x7b0400000020 by main thread:
    #0 fovea::v1::Frame::set_width(int) {SRC}/build-tsan/proto/fovea/v1/frame.pb.h:910 (server+0x30)
    #1 TestBody {SRC}/tests/server/server_e2e_test.cc:50 (server+0x40)

SUMMARY: ThreadSanitizer: data race {SRC}/build-tsan/proto/fovea/v1/frame.pb.h:900 in fovea::v1::Frame::width() const
==================
"""

# gRPC's interceptor state, set on two of gRPC's threads, ordered by a lock
# inside libgrpc++ that TSan cannot see; our test body is only at the
# bottom of the stacks. The library's.
GRPC_INTERNAL = f"""==================
WARNING: ThreadSanitizer: data race (pid=13)
  Read of size 8 at 0x7b9c00010c00 by thread T13:
    #0 std::swap<std::_Any_data>(std::_Any_data&, std::_Any_data&) /usr/include/c++/12/bits/move.h:205 (server_startup_test+0xcd8e8)
    #1 std::function<grpc::Status (void const*)>::swap(std::function<grpc::Status (void const*)>&) /usr/include/c++/12/bits/std_function.h:558 (server_startup_test+0xcd8e8)
    #2 grpc::internal::InterceptorBatchMethodsImpl::SetSendMessage(grpc::ByteBuffer*, void const**, bool*, std::function<grpc::Status (void const*)>) /usr/include/grpcpp/impl/codegen/interceptor_common.h:148 (server_startup_test+0xcd8e8)
    #3 <null> <null> (libgrpc++.so.1.51+0x897ba)

  Previous write of size 8 at 0x7b9c00010c00 by thread T12:
    #0 operator new(unsigned long) ../../../../src/libsanitizer/tsan/tsan_new_delete.cpp:64 (libtsan.so.2+0x87323)
    #1 grpc_tcp_client_create_from_prepared_fd <null> (libgrpc.so.29+0x41eeb0)
    #2 fovea::server::testing::HealthStatus() {SRC}/tests/server/test_util.cc:116 (server_startup_test+0x56d3b)
    #3 TestBody {SRC}/tests/server/server_startup_test.cc:45 (server_startup_test+0x48a53)

SUMMARY: ThreadSanitizer: data race /usr/include/c++/12/bits/move.h:205 in std::swap<std::_Any_data>(std::_Any_data&, std::_Any_data&)
==================
"""


def run(*logs):
    with tempfile.TemporaryDirectory() as folder:
        paths = []
        for i, text in enumerate(logs):
            path = Path(folder) / f"report.{i}"
            path.write_text(text)
            paths.append(str(path))
        result = subprocess.run(
            [sys.executable, str(SCRIPT), "--source-dir", SRC, *paths],
            capture_output=True, text=True, check=False)
    return result.returncode, result.stdout


class TsanReportsTest(unittest.TestCase):
    def test_race_in_our_code_reached_from_grpc_fails(self):
        code, out = run(OURS_UNDER_GRPC)
        self.assertEqual(code, 1, out)
        self.assertIn("1 reports in fovea's code", out)
        self.assertIn("fovea::server::Job::Finish()", out)

    def test_generated_code_is_looked_through(self):
        code, out = run(OURS_THROUGH_GENERATED_CODE)
        self.assertEqual(code, 1, out)
        self.assertIn("fovea::server::HandleDetect()", out)

    def test_race_inside_grpc_is_counted_not_failed(self):
        code, out = run(GRPC_INTERNAL)
        self.assertEqual(code, 0, out)
        self.assertIn("0 reports in fovea's code, 1 inside", out)
        self.assertIn("interceptor_common.h", out)

    def test_mixed_logs_fail_and_count_both(self):
        code, out = run(GRPC_INTERNAL + OURS_UNDER_GRPC, GRPC_INTERNAL)
        self.assertEqual(code, 1, out)
        self.assertIn("2 logs, 1 reports in fovea's code, 2 inside", out)

    def test_no_logs_is_clean(self):
        code, out = run()
        self.assertEqual(code, 0, out)


if __name__ == "__main__":
    unittest.main()
