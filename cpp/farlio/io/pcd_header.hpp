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
  std::size_t record_bytes = 0;  ///< bytes of one point (sum of SIZE * COUNT)
  std::size_t data_bytes = 0;    ///< bytes of all points (points * record_bytes) in the binary encodings
};

/// Parses the header at the start of `bytes`; throws InputError naming `file` on a missing,
/// unknown or malformed key, on inconsistent FIELDS/SIZE/TYPE/COUNT/WIDTH/HEIGHT/POINTS, on a
/// COUNT, WIDTH, HEIGHT or POINTS over its limit (size_limits.hpp) and on sizes that overflow.
[[nodiscard]] PcdHeader parse_pcd_header(ByteView bytes, const std::string& file);

/// The header text for `fields` and `points` points in one row.
[[nodiscard]] std::string format_pcd_header(const std::vector<FieldSpec>& fields, std::size_t points,
                                            PcdEncoding encoding);

}  // namespace farlio::io
