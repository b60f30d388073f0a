#include "farlio/io/point_stream_writer.hpp"

#include <bit>
#include <stdexcept>
#include <vector>

#include "farlio/io/pcd_header.hpp"

namespace farlio::io {

std::string ply_vertex_header(std::size_t points, bool intensity) {
  std::string header = "ply\nformat binary_little_endian 1.0\ncomment written by farlio\nelement vertex " +
                       std::to_string(points) + "\nproperty float x\nproperty float y\nproperty float z\n";
  if (intensity) header += "property float intensity\n";
  return header + "end_header\n";
}

PointStreamWriter::PointStreamWriter(const std::filesystem::path& path, std::size_t points)
    : file_(path), announced_(points) {
  static_assert(std::endian::native == std::endian::little, "the writers assume a little endian host");
  const std::string suffix = path.extension().string();
  if (suffix == ".pcd") {
    constexpr ScalarType kFloat32{ScalarKind::Float, sizeof(float)};
    const std::vector<FieldSpec> fields = {
        {"x", kFloat32, 1}, {"y", kFloat32, 1}, {"z", kFloat32, 1}, {"intensity", kFloat32, 1}};
    file_.write(format_pcd_header(fields, points, PcdEncoding::Binary));
  } else if (suffix == ".ply") {
    file_.write(ply_vertex_header(points, true));
  } else {
    throw std::invalid_argument(path.string() + ": a streamed point cloud is .pcd or .ply");
  }
}

void PointStreamWriter::append(std::span<const Vec3f> points, std::span<const float> intensity) {
  if (intensity.size() != points.size()) {
    throw std::invalid_argument(file_.path().string() + ": " + std::to_string(intensity.size()) + " intensities for " +
                                std::to_string(points.size()) + " points");
  }
  // PCD binary and PLY binary little endian store the same record: x y z intensity, float32
  buffer_.clear();
  buffer_.reserve(points.size() * (sizeof(Vec3f) + sizeof(float)));
  for (std::size_t i = 0; i < points.size(); ++i) {
    const auto* p = reinterpret_cast<const unsigned char*>(points[i].data());
    buffer_.insert(buffer_.end(), p, p + sizeof(Vec3f));
    const auto* q = reinterpret_cast<const unsigned char*>(&intensity[i]);
    buffer_.insert(buffer_.end(), q, q + sizeof(float));
  }
  file_.write(buffer_);
  written_ += points.size();
}

void PointStreamWriter::close() {
  if (written_ != announced_) {
    throw std::runtime_error(file_.path().string() + ": " + std::to_string(written_) + " points written, " +
                             std::to_string(announced_) + " announced");
  }
  file_.close();
}

}  // namespace farlio::io
