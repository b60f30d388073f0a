// libFuzzer target: a KITTI .bin scan (float32 x y z intensity per point).
#include "farlio/io/point_cloud_io.hpp"
#include "fuzz_support.hpp"

namespace {
constexpr std::size_t kBytesPerPoint = 16;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace farlio;
  fuzz::expect_input_error_or_success([&] {
    const Scan s = io::parse_kitti_bin(fuzz::bytes(data, size), fuzz::kInputName);
    FARLIO_FUZZ_CHECK(s.size() * kBytesPerPoint == size && s.intensity.size() == s.size());
  });
  return 0;
}
