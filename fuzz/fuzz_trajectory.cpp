// libFuzzer target: one trajectory reader chosen at build time (FARLIO_FUZZ_TRAJECTORY): a TUM
// file (tum), KITTI poses (kitti) or a times file (times).
#include <cstdint>
#include <string_view>
#include <vector>

#include "farlio/io/trajectory_io.hpp"
#include "fuzz_support.hpp"

namespace {
constexpr std::string_view kReader = FARLIO_FUZZ_TRAJECTORY;
static_assert(kReader == "tum" || kReader == "kitti" || kReader == "times",
              "FARLIO_FUZZ_TRAJECTORY is tum, kitti or times");
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace farlio;
  fuzz::expect_input_error_or_success([&] {
    auto in = fuzz::text_stream(data, size);
    io::Warnings warnings;
    if constexpr (kReader == "tum") {
      (void)io::parse_tum(in, fuzz::kInputName, &warnings);
    } else if constexpr (kReader == "kitti") {
      (void)io::parse_kitti(in, fuzz::kInputName, nullptr, &warnings);
    } else {
      FARLIO_FUZZ_CHECK(!io::parse_stamps(in, fuzz::kInputName, &warnings).empty());
    }
    FARLIO_FUZZ_CHECK(warnings.size() <= 1);  // only the last line can be torn
  });
  return 0;
}
