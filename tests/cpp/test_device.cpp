// The runtime choice of the backend: device names, auto's fallback to the CPU with a message,
// and a clear error when cuda is asked for and cannot be had.
#include <gtest/gtest.h>

#include "farlio/core/config_fields.hpp"
#include "farlio/core/device.hpp"
#include "farlio/pipeline/backend_availability.hpp"
#include "farlio/pipeline/scan_pipeline.hpp"
#include "sim_recording.hpp"

using namespace farlio;

TEST(Device, NamesRoundTripAndBadNamesAreErrors) {
  for (const Device d : {Device::Cpu, Device::Cuda, Device::Auto}) EXPECT_EQ(parse_device(device_name(d)), d);
  try {
    parse_device("gpu", "--device");
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("--device"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("'gpu'"), std::string::npos) << e.what();
  }
  Config c;
  set_config_field(c, "device", "cpu");
  EXPECT_EQ(c.device, Device::Cpu);
  EXPECT_EQ(get_config_field(c, "device"), "cpu");
  EXPECT_THROW(set_config_field(c, "device", "tpu"), std::invalid_argument);
}

TEST(Device, CpuIsAlwaysCpu) {
  std::string message;
  EXPECT_EQ(resolve_device(Device::Cpu, &message), Device::Cpu);
  EXPECT_TRUE(message.empty());
  Config c;
  c.device = Device::Cpu;
  const pipeline::ScanPipeline p(c);
  EXPECT_EQ(p.backend().device(), Device::Cpu);
  EXPECT_TRUE(p.device_message().empty());
}

TEST(Device, AutoFallsBackToTheCpuWithAMessageWithoutAGpu) {
  if (cuda_device_count() > 0) GTEST_SKIP() << "a CUDA device is present: auto picks it";
  std::string message;
  EXPECT_EQ(resolve_device(Device::Auto, &message), Device::Cpu);
  EXPECT_NE(message.find("running on the CPU"), std::string::npos) << message;
  EXPECT_EQ(message.find('\n'), std::string::npos) << "one line";
  Config c;  // device auto is the default
  const pipeline::ScanPipeline p(c);
  EXPECT_EQ(p.backend().device(), Device::Cpu);
  EXPECT_EQ(p.device_message(), message);
}

TEST(Device, CudaWithoutAGpuIsAClearError) {
  if (cuda_device_count() > 0) GTEST_SKIP() << "a CUDA device is present";
  Config c;
  c.device = Device::Cuda;
  try {
    const pipeline::ScanPipeline p(c);
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("device cuda was requested"), std::string::npos) << what;
    EXPECT_NE(what.find(cuda_compiled() ? "no CUDA device" : "no CUDA backend"), std::string::npos) << what;
  }
}

TEST(Device, OnTheCpuAStagedScanChangesNothing) {
  // the CPU backend has nothing to move: staging the next scan leaves every result as it was
  constexpr std::size_t kFirst = 25, kScans = 5;  // generated urban starts with 2.5 s at rest
  const std::vector<Scan> scans = test::generated_scans(sim::Profile::Urban, kFirst, kScans);
  Config c;
  c.device = Device::Cpu;
  c.registration.time_budget_factor = 1e6;  // compare results, not the time budget
  pipeline::ScanPipeline plain(c), staged(c);
  for (std::size_t i = 0; i < scans.size(); ++i) {
    if (i + 1 < scans.size()) staged.stage_next(scans[i + 1]);
    const auto a = plain.process(scans[i]);
    const auto b = staged.process(scans[i]);
    EXPECT_FALSE(staged.backend().last_scan_was_staged());
    EXPECT_EQ(a.pose.translation(), b.pose.translation());
    EXPECT_EQ(a.kept_points, b.kept_points);
  }
  EXPECT_EQ(staged.frames(), kScans);
}
