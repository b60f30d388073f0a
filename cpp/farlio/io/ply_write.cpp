// Writing binary little endian PLY vertices: float x y z [intensity].
#include <bit>
#include <cstring>
#include <string>

#include "farlio/core/error.hpp"
#include "farlio/io/file_bytes.hpp"
#include "farlio/io/point_cloud_io.hpp"
#include "farlio/io/point_stream_writer.hpp"

namespace farlio::io {

void write_ply(const std::filesystem::path& path, const std::vector<Vec3f>& points,
               const std::vector<float>* intensity) {
  static_assert(std::endian::native == std::endian::little, "the PLY writer assumes a little endian host");
  const bool with_intensity = intensity != nullptr;
  if (with_intensity && intensity->size() != points.size()) {
    throw InputError(path.string() + ": " + std::to_string(intensity->size()) + " intensities for " +
                     std::to_string(points.size()) + " points");
  }
  const std::string header = ply_vertex_header(points.size(), with_intensity);
  Bytes out(header.begin(), header.end());
  const std::size_t point_bytes = sizeof(Vec3f) + (with_intensity ? sizeof(float) : 0);
  out.reserve(out.size() + points.size() * point_bytes);
  for (std::size_t i = 0; i < points.size(); ++i) {
    const auto* p = reinterpret_cast<const unsigned char*>(points[i].data());
    out.insert(out.end(), p, p + sizeof(Vec3f));
    if (with_intensity) {
      const auto* q = reinterpret_cast<const unsigned char*>(&(*intensity)[i]);
      out.insert(out.end(), q, q + sizeof(float));
    }
  }
  write_file_bytes(path, out);
}

}  // namespace farlio::io
