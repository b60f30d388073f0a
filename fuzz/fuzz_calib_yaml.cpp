// libFuzzer target: calib.yaml (T_imu_lidar, gravity, rates) through yaml-cpp.
#include <string>

#include "farlio/io/calibration.hpp"
#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace farlio;
  fuzz::expect_input_error_or_success(
      [&] { (void)io::parse_calibration(std::string(reinterpret_cast<const char*>(data), size), fuzz::kInputName); });
  return 0;
}
