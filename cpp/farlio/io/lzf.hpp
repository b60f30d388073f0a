#pragma once
// LZF compression (the format of liblzf, used by PCD "binary_compressed").
//
// A stream is a sequence of chunks, each starting with a control byte c:
//   c < 32  : a literal run; the next c + 1 bytes are copied to the output.
//   c >= 32 : a back-reference of length (c >> 5) + 2; if (c >> 5) == 7 one more byte follows
//             whose value is added to the length. The next byte b gives the distance
//             ((c & 0x1f) << 8 | b) + 1 back from the current output position.
#include <cstddef>
#include <span>
#include <stdexcept>
#include <vector>

namespace farlio::io {

/// Corrupt LZF data; callers wrap it into an InputError naming their file.
class LzfError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Compresses `in` (hash-table matching of 3-byte sequences). Never fails; incompressible data
/// grows by at most one byte in 32 plus one.
[[nodiscard]] std::vector<unsigned char> lzf_compress(std::span<const unsigned char> in);

/// Decompresses `in`, which must expand to exactly `expected_size` bytes. Throws LzfError on an
/// `expected_size` over 88 times the input (the most LZF can expand; checked before allocating),
/// a reference before the start of the output, a chunk running past the input, or a size mismatch.
[[nodiscard]] std::vector<unsigned char> lzf_decompress(std::span<const unsigned char> in, std::size_t expected_size);

}  // namespace farlio::io
