// libFuzzer target: the LZF decoder on any bytes (the first four give the expected size, as
// the size prefix of PCD binary_compressed does), and the encoder by a round trip of the input.
#include <algorithm>
#include <vector>

#include "farlio/io/lzf.hpp"
#include "fuzz_support.hpp"

namespace {
constexpr std::size_t kSizeBytes = 4;
constexpr unsigned kByteBits = 8;
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace farlio::io;
  const std::span<const unsigned char> in(data, size);
  // Round trip: whatever the encoder makes, the decoder gives back exactly.
  const std::vector<unsigned char> packed = lzf_compress(in);
  const std::vector<unsigned char> unpacked = lzf_decompress(packed, size);
  FARLIO_FUZZ_CHECK(std::equal(unpacked.begin(), unpacked.end(), in.begin(), in.end()));
  // Decoding: corrupt data is an LzfError, never a read or write out of bounds.
  if (size < kSizeBytes) return 0;
  std::size_t expected = 0;
  for (std::size_t k = 0; k < kSizeBytes; ++k) expected |= std::size_t{data[k]} << (kByteBits * k);
  try {
    const auto out = lzf_decompress(in.subspan(kSizeBytes), expected);
    FARLIO_FUZZ_CHECK(out.size() == expected);
  } catch (const LzfError&) {
  }
  return 0;
}
