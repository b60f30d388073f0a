#pragma once
// A point cloud written as it comes, in pieces, so that the whole cloud never has to be in
// memory: binary PCD (.pcd) or binary little endian PLY (.ply) with float32 x y z intensity, the
// point count announced in the header up front (the caller knows it) and checked at close.
#include <cstddef>
#include <filesystem>
#include <span>
#include <string>

#include "farlio/core/types.hpp"
#include "farlio/io/file_bytes.hpp"

namespace farlio::io {

/// The PLY header of `points` vertices with float x y z [intensity] (write_ply's too).
[[nodiscard]] std::string ply_vertex_header(std::size_t points, bool intensity);

class PointStreamWriter {
 public:
  /// Creates the file (the format from its suffix, .pcd or .ply; std::invalid_argument for
  /// another) and writes the header of `points` points.
  PointStreamWriter(const std::filesystem::path& path, std::size_t points);
  /// Appends points with their intensities (one each).
  void append(std::span<const Vec3f> points, std::span<const float> intensity);
  /// Closes the file; std::runtime_error naming it when fewer or more points came than announced.
  void close();

 private:
  OutputFile file_;
  std::size_t announced_ = 0, written_ = 0;
  Bytes buffer_;
};

}  // namespace farlio::io
