// libFuzzer target: a whole PCD file (header and data; ascii, binary or binary_compressed).
#include "farlio/io/point_cloud_io.hpp"
#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace farlio;
  fuzz::expect_input_error_or_success(
      [&] { FARLIO_FUZZ_CHECK(fuzz::consistent(io::parse_pcd(fuzz::bytes(data, size), fuzz::kInputName))); });
  return 0;
}
