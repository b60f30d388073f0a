#include <gtest/gtest.h>

#include <random>

#include "farlio/io/lzf.hpp"

using namespace farlio::io;

namespace {
std::vector<unsigned char> random_bytes(std::size_t n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> b(0, 255);
  std::vector<unsigned char> v(n);
  for (auto& x : v) x = static_cast<unsigned char>(b(rng));
  return v;
}
}  // namespace

TEST(Lzf, RoundTripRandomData) {
  for (std::size_t n : {0u, 1u, 2u, 3u, 31u, 32u, 33u, 1000u, 100000u}) {
    const auto in = random_bytes(n, static_cast<unsigned>(n) + 7);
    const auto packed = lzf_compress(in);
    EXPECT_LE(packed.size(), n + n / 32 + 1) << n;
    EXPECT_EQ(lzf_decompress(packed, n), in) << n;
  }
}

TEST(Lzf, RepetitiveDataShrinksAndRoundTrips) {
  std::vector<unsigned char> in;
  const std::string motif = "farlio-lzf-";
  while (in.size() < 200000) in.insert(in.end(), motif.begin(), motif.end());
  in.insert(in.end(), 5000, 0);  // a long run: overlapping back-references
  const auto packed = lzf_compress(in);
  EXPECT_LT(packed.size(), in.size() / 20);
  EXPECT_EQ(lzf_decompress(packed, in.size()), in);
}

TEST(Lzf, MixedDataWithDistantRepeats) {
  auto in = random_bytes(20000, 3);
  // A repeat 5000 bytes back (inside the 8 KiB window) compresses; one 19900 bytes back cannot.
  const auto near = std::vector<unsigned char>(in.begin() + 15000, in.begin() + 19000);
  const auto far = std::vector<unsigned char>(in.begin() + 100, in.begin() + 4100);
  in.insert(in.end(), near.begin(), near.end());
  const std::size_t random_part = 20000 + 20000 / 32 + 1;
  const auto packed = lzf_compress(in);
  EXPECT_LT(packed.size(), random_part + near.size() / 10);
  EXPECT_EQ(lzf_decompress(packed, in.size()), in);
  in.insert(in.end(), far.begin(), far.end());  // now ~28000 bytes back: out of reach
  const auto packed_far = lzf_compress(in);
  EXPECT_GT(packed_far.size(), packed.size() + far.size());
  EXPECT_EQ(lzf_decompress(packed_far, in.size()), in);
}

TEST(Lzf, DecodesHandMadeStream) {
  // literal "ab", then back-reference distance 2 length 4 -> "ababab"
  const std::vector<unsigned char> s = {0x01, 'a', 'b', (2 << 5) | 0, 0x01};
  const std::vector<unsigned char> want = {'a', 'b', 'a', 'b', 'a', 'b'};
  EXPECT_EQ(lzf_decompress(s, want.size()), want);
}

TEST(Lzf, CorruptDataThrows) {
  // back-reference before the start of the output
  EXPECT_THROW((void)lzf_decompress(std::vector<unsigned char>{0x00, 'a', (1 << 5), 0x05}, 4), LzfError);
  // literal run past the end of the input
  EXPECT_THROW((void)lzf_decompress(std::vector<unsigned char>{0x05, 'a'}, 6), LzfError);
  // expands to fewer bytes than expected
  EXPECT_THROW((void)lzf_decompress(std::vector<unsigned char>{0x00, 'a'}, 2), LzfError);
  // expands beyond the expected size
  EXPECT_THROW((void)lzf_decompress(std::vector<unsigned char>{0x01, 'a', 'b'}, 1), LzfError);
  // missing distance byte
  EXPECT_THROW((void)lzf_decompress(std::vector<unsigned char>{0x00, 'a', (1 << 5)}, 4), LzfError);
  // missing extra length byte
  EXPECT_THROW((void)lzf_decompress(std::vector<unsigned char>{0x00, 'a', (7 << 5)}, 20), LzfError);
}
