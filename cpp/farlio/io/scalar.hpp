#pragma once
// Binary scalar types of point cloud fields (PCD F/I/U, PLY float/int/...) and loading them.
#include <cstddef>
#include <optional>
#include <string>

namespace farlio::io {

enum class ScalarKind { Float, Int, Uint };

struct ScalarType {
  ScalarKind kind = ScalarKind::Float;
  std::size_t size_bytes = 4;

  [[nodiscard]] bool is_integer() const { return kind != ScalarKind::Float; }
  /// Float with 4 or 8 bytes, or an integer with 1, 2, 4 or 8 bytes.
  [[nodiscard]] bool is_valid() const;
  friend bool operator==(const ScalarType&, const ScalarType&) = default;
};

/// PLY type names: char uchar short ushort int uint float double and int8 ... float64.
[[nodiscard]] std::optional<ScalarType> ply_scalar_type(const std::string& name);

/// Loads one value of `type` at `p` as a double; `big_endian` is the byte order of the data.
[[nodiscard]] double load_scalar(const unsigned char* p, ScalarType type, bool big_endian);

}  // namespace farlio::io
