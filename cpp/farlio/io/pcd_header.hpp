#pragma once
// The header of a PCD v0.7 file.
#include <cstddef>
#include <string>
#include <vector>

#include "farlio/io/file_bytes.hpp"
#include "farlio/io/point_cloud_io.hpp"
#include "farlio/io/point_fields.hpp"

namespace farlio::io {

struct PcdHeader {
  std::vector<FieldSpec> fields;
  std::size_t width = 0;
  std::size_t height = 1;
  std::size_t points = 0;
  PcdEncoding encoding = PcdEncoding::Binary;
  std::size_t data_offset = 0;   ///< first byte after the DATA line
  std::size_t header_lines = 0;  ///< lines up to and including the DATA line

  /// Bytes of one point (sum of SIZE * COUNT).
  [[nodiscard]] std::size_t record_bytes() const;
};

/// Parses the header at the start of `bytes`; throws InputError naming `file` on a missing,
/// unknown or malformed key or on inconsistent FIELDS/SIZE/TYPE/COUNT/WIDTH/HEIGHT/POINTS.
[[nodiscard]] PcdHeader parse_pcd_header(const Bytes& bytes, const std::string& file);

/// The header text for `fields` and `points` points in one row.
[[nodiscard]] std::string format_pcd_header(const std::vector<FieldSpec>& fields, std::size_t points,
                                            PcdEncoding encoding);

}  // namespace farlio::io
