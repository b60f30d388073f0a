#pragma once
// Limits on the sizes a file may announce, and size arithmetic that cannot wrap around.
//
// Every size read from a header (PCD COUNT, WIDTH, HEIGHT, POINTS; PLY element counts) is
// checked against a limit before it is used, and every product or sum of such sizes (record
// sizes, data sizes, offsets) goes through checked_mul/checked_add, so that a crafted header
// cannot make a size wrap to a small value, pass a bounds check and send a read outside the
// data. The limits are far above any real file; the data must still hold what is announced.
#include <cstddef>
#include <optional>
#include <string>

namespace farlio::io {

/// Most points a point cloud file may announce: 2^32 (48 GiB of float32 x y z alone).
inline constexpr std::size_t kMaxCloudPoints = std::size_t{1} << 32;
/// Most values of one field per point (PCD COUNT); descriptors such as histograms use hundreds.
inline constexpr std::size_t kMaxFieldCount = std::size_t{1} << 20;

/// a * b and a + b, or nullopt when the result does not fit a size_t.
[[nodiscard]] std::optional<std::size_t> checked_mul(std::size_t a, std::size_t b);
[[nodiscard]] std::optional<std::size_t> checked_add(std::size_t a, std::size_t b);

/// Throws InputError "<file>: <what> is over the limit of <limit>" when value > limit; `what`
/// names the value and where it comes from, e.g. "COUNT 4096 of field 'pad'".
void require_within_limit(std::size_t value, std::size_t limit, const std::string& file, const std::string& what);

}  // namespace farlio::io
