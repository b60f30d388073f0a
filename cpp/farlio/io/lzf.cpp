#include "farlio/io/lzf.hpp"

#include <algorithm>
#include <cstdint>
#include <string>

namespace farlio::io {
namespace {

constexpr std::size_t kMaxLiteralRun = 32;                              // control byte 0..31
constexpr std::size_t kMinMatch = 3;                                    // shortest back-reference worth encoding
constexpr std::size_t kLengthBias = 2;                                  // encoded length = match length - 2
constexpr std::size_t kShortLengthMax = 7;                              // (c >> 5) == 7: an extra length byte follows
constexpr std::size_t kMaxMatch = kShortLengthMax + 255 + kLengthBias;  // 264
constexpr std::size_t kMaxDistance = std::size_t{1} << 13;              // 8192 (13-bit distance - 1)
constexpr unsigned kLiteralLimit = 32;                                  // control bytes below this are literal runs
constexpr unsigned kLengthShift = 5;
constexpr unsigned kDistanceHighMask = 0x1f;
constexpr unsigned kHashBits = 14;
constexpr std::size_t kHashSize = std::size_t{1} << kHashBits;
constexpr std::uint32_t kHashMultiplier = 2654435761u;  // Knuth's multiplicative hash
constexpr std::size_t kNoEntry = static_cast<std::size_t>(-1);
// The most output one input byte can give: a long back-reference (3 bytes) copies kMaxMatch bytes.
constexpr std::size_t kLongReferenceBytes = 3;
constexpr std::size_t kMaxExpansion = kMaxMatch / kLongReferenceBytes;  // 88

std::size_t hash3(const unsigned char* p) {
  const std::uint32_t v = (std::uint32_t{p[0]} << 16) | (std::uint32_t{p[1]} << 8) | p[2];
  return static_cast<std::size_t>((v * kHashMultiplier) >> (32 - kHashBits));
}

class LzfEncoder {
 public:
  explicit LzfEncoder(std::size_t reserve) { out_.reserve(reserve); }

  void literal(unsigned char b) {
    if (lit_len_ == 0) {
      lit_pos_ = out_.size();
      out_.push_back(0);
    }
    out_.push_back(b);
    if (++lit_len_ == kMaxLiteralRun) flush_literals();
  }

  void match(std::size_t distance, std::size_t length) {
    flush_literals();
    const std::size_t enc_len = length - kLengthBias;
    const std::size_t enc_dist = distance - 1;
    const auto high = static_cast<unsigned char>(enc_dist >> 8);
    const auto low = static_cast<unsigned char>(enc_dist & 0xff);
    if (enc_len < kShortLengthMax) {
      out_.push_back(static_cast<unsigned char>((enc_len << kLengthShift) | high));
    } else {
      out_.push_back(static_cast<unsigned char>((kShortLengthMax << kLengthShift) | high));
      out_.push_back(static_cast<unsigned char>(enc_len - kShortLengthMax));
    }
    out_.push_back(low);
  }

  std::vector<unsigned char> finish() {
    flush_literals();
    return std::move(out_);
  }

 private:
  void flush_literals() {
    if (lit_len_ == 0) return;
    out_[lit_pos_] = static_cast<unsigned char>(lit_len_ - 1);
    lit_len_ = 0;
  }

  std::vector<unsigned char> out_;
  std::size_t lit_pos_ = 0;
  std::size_t lit_len_ = 0;
};

}  // namespace

std::vector<unsigned char> lzf_compress(std::span<const unsigned char> in) {
  const std::size_t n = in.size();
  LzfEncoder enc(n + n / kMaxLiteralRun + 1);
  std::vector<std::size_t> table(kHashSize, kNoEntry);
  std::size_t ip = 0;
  while (ip < n) {
    if (ip + kMinMatch <= n) {
      const std::size_t h = hash3(&in[ip]);
      const std::size_t ref = table[h];
      table[h] = ip;
      if (ref != kNoEntry && ip - ref <= kMaxDistance && in[ref] == in[ip] && in[ref + 1] == in[ip + 1] &&
          in[ref + 2] == in[ip + 2]) {
        const std::size_t max_len = std::min(kMaxMatch, n - ip);
        std::size_t len = kMinMatch;
        while (len < max_len && in[ref + len] == in[ip + len]) ++len;
        enc.match(ip - ref, len);
        // Index the positions inside the match so later data can refer to them.
        for (std::size_t k = ip + 1; k < ip + len && k + kMinMatch <= n; ++k) table[hash3(&in[k])] = k;
        ip += len;
        continue;
      }
    }
    enc.literal(in[ip]);
    ++ip;
  }
  return enc.finish();
}

std::vector<unsigned char> lzf_decompress(std::span<const unsigned char> in, std::size_t expected_size) {
  // Checked before reserving, so that a size field cannot make us allocate what the data cannot fill.
  if (in.size() < expected_size / kMaxExpansion) {
    throw LzfError("LZF data of " + std::to_string(in.size()) + " bytes cannot expand to " +
                   std::to_string(expected_size) + " bytes (at most " + std::to_string(kMaxExpansion) + " times)");
  }
  std::vector<unsigned char> out;
  out.reserve(expected_size);
  std::size_t ip = 0;
  const std::size_t n = in.size();
  while (ip < n) {
    const unsigned c = in[ip++];
    if (c < kLiteralLimit) {
      const std::size_t run = c + 1;
      if (ip + run > n) {
        throw LzfError("LZF literal run of " + std::to_string(run) + " bytes at input offset " +
                       std::to_string(ip - 1) + " runs past the end of the compressed data");
      }
      if (out.size() + run > expected_size) {
        throw LzfError("LZF data expands beyond the expected " + std::to_string(expected_size) + " bytes");
      }
      out.insert(out.end(), in.begin() + static_cast<std::ptrdiff_t>(ip),
                 in.begin() + static_cast<std::ptrdiff_t>(ip + run));
      ip += run;
      continue;
    }
    std::size_t len = c >> kLengthShift;
    if (len == kShortLengthMax) {
      if (ip >= n) throw LzfError("LZF back-reference length byte missing at end of data");
      len += in[ip++];
    }
    len += kLengthBias;
    if (ip >= n) throw LzfError("LZF back-reference distance byte missing at end of data");
    const std::size_t distance = ((std::size_t{c & kDistanceHighMask} << 8) | in[ip++]) + 1;
    if (distance > out.size()) {
      throw LzfError("LZF back-reference " + std::to_string(distance) + " bytes back at output offset " +
                     std::to_string(out.size()) + " points before the start of the data");
    }
    if (out.size() + len > expected_size) {
      throw LzfError("LZF data expands beyond the expected " + std::to_string(expected_size) + " bytes");
    }
    std::size_t ref = out.size() - distance;
    for (std::size_t k = 0; k < len; ++k) out.push_back(out[ref++]);  // may overlap: byte by byte
  }
  if (out.size() != expected_size) {
    throw LzfError("LZF data expands to " + std::to_string(out.size()) + " bytes, expected " +
                   std::to_string(expected_size));
  }
  return out;
}

}  // namespace farlio::io
