// KITTI Velodyne .bin: float32 x y z intensity per point, little endian, no header.
#include <bit>
#include <cstring>
#include <string>

#include "farlio/core/error.hpp"
#include "farlio/io/file_bytes.hpp"
#include "farlio/io/point_cloud_io.hpp"
#include "farlio/io/scalar.hpp"

namespace farlio::io {
namespace {
constexpr std::size_t kFloatsPerPoint = 4;
constexpr std::size_t kBytesPerPoint = kFloatsPerPoint * sizeof(float);
constexpr ScalarType kFloat32{ScalarKind::Float, sizeof(float)};
constexpr bool kLittleEndian = false;  // the `big_endian` argument of load_scalar
}  // namespace

Scan read_kitti_bin(const std::filesystem::path& path) { return parse_kitti_bin(read_file_bytes(path), path.string()); }

Scan parse_kitti_bin(ByteView bytes, const std::string& file) {
  if (bytes.size() % kBytesPerPoint != 0) {
    throw InputError(file + ": size " + std::to_string(bytes.size()) + " bytes is not a multiple of " +
                     std::to_string(kBytesPerPoint) + " (float32 x y z intensity per point; truncated?)");
  }
  const std::size_t n = bytes.size() / kBytesPerPoint;
  Scan scan;
  scan.points.resize(n);
  scan.intensity.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const unsigned char* p = bytes.data() + i * kBytesPerPoint;
    auto at = [&](std::size_t k) {
      return static_cast<float>(load_scalar(p + k * sizeof(float), kFloat32, kLittleEndian));
    };
    scan.points[i] = Vec3f(at(0), at(1), at(2));
    scan.intensity[i] = at(3);
  }
  return scan;
}

void write_kitti_bin(const std::filesystem::path& path, const Scan& scan) {
  static_assert(std::endian::native == std::endian::little, "KITTI .bin writer assumes a little endian host");
  scan.validate(path.string());
  Bytes bytes(scan.size() * kBytesPerPoint);
  const bool has_intensity = !scan.intensity.empty();
  for (std::size_t i = 0; i < scan.size(); ++i) {
    const float v[kFloatsPerPoint] = {scan.points[i].x(), scan.points[i].y(), scan.points[i].z(),
                                      has_intensity ? scan.intensity[i] : 0.0f};
    std::memcpy(bytes.data() + i * kBytesPerPoint, v, kBytesPerPoint);
  }
  write_file_bytes(path, bytes);
}

}  // namespace farlio::io
