// Writing PCD v0.7 files with fields x y z [intensity] [t] float32 and [sensor_id] uint8.
#include <bit>
#include <cstdint>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string>

#include "farlio/io/file_bytes.hpp"
#include "farlio/io/lzf.hpp"
#include "farlio/io/pcd_header.hpp"
#include "farlio/io/point_cloud_io.hpp"
#include "farlio/io/text_number.hpp"

namespace farlio::io {
namespace {

static_assert(std::endian::native == std::endian::little, "the PCD writer assumes a little endian host");

constexpr ScalarType kFloat32{ScalarKind::Float, sizeof(float)};
constexpr ScalarType kUint8{ScalarKind::Uint, sizeof(std::uint8_t)};

/// The columns of a scan as written: each a name, a type and a way to get point i's bytes.
struct Column {
  FieldSpec spec;
  const unsigned char* data = nullptr;  ///< contiguous values, spec.type.size_bytes each
};

std::vector<Column> columns_of(const Scan& scan) {
  auto bytes_of = [](const auto* p) { return reinterpret_cast<const unsigned char*>(p); };
  std::vector<Column> cols;
  const unsigned char* pts = bytes_of(scan.points.data());
  // Eigen::Vector3f is three packed floats, so x, y, z are strided by 3 floats.
  static_assert(sizeof(Vec3f) == 3 * sizeof(float));
  cols.push_back({{"x", kFloat32, 1}, pts});
  cols.push_back({{"y", kFloat32, 1}, pts + sizeof(float)});
  cols.push_back({{"z", kFloat32, 1}, pts + 2 * sizeof(float)});
  if (!scan.intensity.empty()) cols.push_back({{"intensity", kFloat32, 1}, bytes_of(scan.intensity.data())});
  if (!scan.time_s.empty()) cols.push_back({{"t", kFloat32, 1}, bytes_of(scan.time_s.data())});
  if (!scan.sensor_id.empty()) cols.push_back({{"sensor_id", kUint8, 1}, bytes_of(scan.sensor_id.data())});
  return cols;
}

/// Bytes of point i in column c (points are strided by a whole Vec3f).
const unsigned char* value_at(const Column& c, std::size_t column_index, std::size_t i) {
  constexpr std::size_t kXyzColumns = 3;
  const std::size_t stride = column_index < kXyzColumns ? sizeof(Vec3f) : c.spec.type.size_bytes;
  return c.data + i * stride;
}

void append_u32(Bytes& out, std::size_t v, const std::string& file) {
  if (v > std::numeric_limits<std::uint32_t>::max()) {
    throw std::runtime_error(file + ": binary_compressed block exceeds 4 GiB");
  }
  const auto u = static_cast<std::uint32_t>(v);
  const auto* p = reinterpret_cast<const unsigned char*>(&u);
  out.insert(out.end(), p, p + sizeof(u));
}

}  // namespace

void write_pcd(const std::filesystem::path& path, const Scan& scan, PcdEncoding encoding) {
  const std::string file = path.string();
  scan.validate(file);
  const auto cols = columns_of(scan);
  std::vector<FieldSpec> specs;
  for (const auto& c : cols) specs.push_back(c.spec);
  const std::string header = format_pcd_header(specs, scan.size(), encoding);
  Bytes out(header.begin(), header.end());
  const std::size_t n = scan.size();
  if (encoding == PcdEncoding::Ascii) {
    std::string text;
    for (std::size_t i = 0; i < n; ++i) {
      for (std::size_t k = 0; k < cols.size(); ++k) {
        if (k) text += ' ';
        const unsigned char* p = value_at(cols[k], k, i);
        if (cols[k].spec.type == kUint8) {
          text += std::to_string(unsigned{*p});
        } else {
          float v;
          std::memcpy(&v, p, sizeof(v));
          text += format_number(v);
        }
      }
      text += '\n';
    }
    out.insert(out.end(), text.begin(), text.end());
  } else if (encoding == PcdEncoding::Binary) {
    for (std::size_t i = 0; i < n; ++i) {
      for (std::size_t k = 0; k < cols.size(); ++k) {
        const unsigned char* p = value_at(cols[k], k, i);
        out.insert(out.end(), p, p + cols[k].spec.type.size_bytes);
      }
    }
  } else {
    Bytes soa;
    for (std::size_t k = 0; k < cols.size(); ++k) {
      for (std::size_t i = 0; i < n; ++i) {
        const unsigned char* p = value_at(cols[k], k, i);
        soa.insert(soa.end(), p, p + cols[k].spec.type.size_bytes);
      }
    }
    const auto packed = lzf_compress(soa);
    append_u32(out, packed.size(), file);
    append_u32(out, soa.size(), file);
    out.insert(out.end(), packed.begin(), packed.end());
  }
  write_file_bytes(path, out);
}

}  // namespace farlio::io
