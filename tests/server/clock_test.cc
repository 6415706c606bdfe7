#include "server/clock.h"

#include <gtest/gtest.h>

namespace fovea::server {
namespace {

TEST(DeadlinePassedTest, ComparesOnTheDeadlinesOwnClock) {
  const gpr_timespec now = gpr_now(GPR_CLOCK_REALTIME);
  EXPECT_TRUE(DeadlinePassed(
      gpr_time_sub(now, gpr_time_from_seconds(1, GPR_TIMESPAN))));
  EXPECT_FALSE(DeadlinePassed(
      gpr_time_add(now, gpr_time_from_seconds(60, GPR_TIMESPAN))));
  EXPECT_FALSE(DeadlinePassed(gpr_inf_future(GPR_CLOCK_REALTIME)));
  EXPECT_FALSE(DeadlinePassed(gpr_inf_future(GPR_CLOCK_MONOTONIC)));
}

// The largest grpc-timeout, 99999999 hours: about the year 13400, beyond
// the year 2262 where a nanosecond std::chrono clock overflows.
TEST(DeadlinePassedTest, TheLargestGrpcTimeoutIsInTheFuture) {
  const gpr_timespec far =
      gpr_time_add(gpr_now(GPR_CLOCK_MONOTONIC),
                   gpr_time_from_hours(99999999, GPR_TIMESPAN));
  EXPECT_FALSE(DeadlinePassed(far));
}

}  // namespace
}  // namespace fovea::server
