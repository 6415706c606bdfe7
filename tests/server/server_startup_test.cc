// What the server reports before it has served anything: health while the
// warm-up runs, and the metric series that exist from start-up.
//
// The metric series are process-wide, so this binary must not run a
// Detect call (the warm-up's Detect records no metrics): a test here that
// did would make the zero counts below depend on test order.

#include <grpcpp/grpcpp.h>

#include <string>

#include "core/base/mutex.h"
#include "core/pipeline/detect.h"
#include "gtest/gtest.h"
#include "server/server.h"
#include "tests/server/server_fixture.h"
#include "tests/server/test_util.h"

namespace fovea::server {
namespace {

using ::fovea::server::testing::HealthStatus;
using ::fovea::server::testing::kStartTimeout;
using ::fovea::server::testing::MetricValue;
using ::fovea::server::testing::ServerTest;
using ::fovea::server::testing::WaitFor;

class StartupTest : public ServerTest {
 protected:
  void TearDown() override {
    // Shutdown joins the warm-up thread: never leave it held.
    if (!release_warm_up_.HasBeenNotified()) release_warm_up_.Notify();
    ServerTest::TearDown();
  }

  Notification release_warm_up_;
};

TEST_F(StartupTest, HealthIsNotServingUntilTheWarmUpCompletes) {
  ServerConfig config = DefaultConfig();
  config.warm_up = true;
  config.before_warm_up = [this] { release_warm_up_.WaitForNotification(); };
  StartServer(config, /*wait_serving=*/false);

  EXPECT_FALSE(server_->warmed_up());
  EXPECT_EQ(HealthStatus(channel_, ""), "NOT_SERVING");
  EXPECT_EQ(HealthStatus(channel_, "fovea.v1.Perception"), "NOT_SERVING");

  release_warm_up_.Notify();
  EXPECT_TRUE(WaitFor(
      [this] {
        return HealthStatus(channel_, "fovea.v1.Perception") == "SERVING";
      },
      kStartTimeout));
  EXPECT_EQ(HealthStatus(channel_, ""), "SERVING");
  EXPECT_TRUE(server_->warmed_up());
}

// Dashboards and alerts see every stage from the start, at zero, even
// when no warm-up Detect ran.
TEST_F(StartupTest, EveryStageSeriesExistsAtZeroWithoutWarmUp) {
  ServerConfig config = DefaultConfig();
  config.warm_up = false;
  StartServer(config);
  const std::string text = Scrape();

  EXPECT_EQ(MetricValue(text, "fovea_stage_duration_seconds_count",
                        {"stage=\"normals\""}),
            0);
  std::vector<std::string> stages = DetectStageNames();
  stages.insert(stages.end(), {"queue", "decode", "encode"});
  for (const std::string& stage : stages) {
    EXPECT_EQ(MetricValue(text, "fovea_stage_duration_seconds_count",
                          {"stage=\"" + stage + "\""}),
              0)
        << stage;
  }
}

}  // namespace
}  // namespace fovea::server
