// libFuzzer target: the data section of a PCD file in one encoding (FARLIO_FUZZ_PCD_ENCODING),
// behind a fixed valid header, so that every mutation goes to the data decoder. The input's
// first two bytes give the number of points (little endian), the rest is the data. The fields
// are those write_pcd writes for a scan with intensity, time and sensor id.
#include <string>
#include <vector>

#include "farlio/io/point_cloud_io.hpp"
#include "fuzz_support.hpp"

namespace {
constexpr std::size_t kCountBytes = 2;
constexpr unsigned kByteBits = 8;
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace farlio;
  if (size < kCountBytes) return 0;
  const std::size_t points = data[0] | (std::size_t{data[1]} << kByteBits);
  const std::string header =
      "# .PCD v0.7\nVERSION 0.7\nFIELDS x y z intensity t sensor_id\nSIZE 4 4 4 4 4 1\nTYPE F F F F F U\n"
      "COUNT 1 1 1 1 1 1\nWIDTH " +
      std::to_string(points) + "\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS " + std::to_string(points) +
      "\nDATA " FARLIO_FUZZ_PCD_ENCODING "\n";
  std::vector<unsigned char> file(header.begin(), header.end());
  file.insert(file.end(), data + kCountBytes, data + size);
  fuzz::expect_input_error_or_success([&] {
    const Scan s = io::parse_pcd(file, fuzz::kInputName);
    FARLIO_FUZZ_CHECK(s.size() == points && fuzz::consistent(s));
  });
  return 0;
}
