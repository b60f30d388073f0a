// libFuzzer target: imu.csv (t_ns,gx,gy,gz,ax,ay,az).
#include <string>
#include <vector>

#include "farlio/io/imu_csv.hpp"
#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace farlio;
  fuzz::expect_input_error_or_success([&] {
    auto in = fuzz::text_stream(data, size);
    std::vector<std::string> warnings;
    const auto samples = io::parse_imu_csv(in, fuzz::kInputName, warnings);
    for (std::size_t k = 1; k < samples.size(); ++k) FARLIO_FUZZ_CHECK(samples[k].stamp_ns > samples[k - 1].stamp_ns);
  });
  return 0;
}
