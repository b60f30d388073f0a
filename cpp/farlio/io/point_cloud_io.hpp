#pragma once
// Point cloud files: PCD (ascii, binary, binary_compressed), PLY (ascii, binary little and big
// endian) and KITTI .bin (float32 x y z intensity). Any of them may be gzip'd (name + ".gz").
// Readers fill Scan::points, and when present intensity, time_s and sensor_id (see
// point_fields.hpp for the field names); the stamps are left 0. Bad input throws InputError
// naming the file; a file that cannot be written throws std::runtime_error naming it.
#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "farlio/core/types.hpp"

namespace farlio::io {

enum class PcdEncoding { Ascii, Binary, BinaryCompressed };

/// "ascii", "binary", "binary_compressed" (the PCD DATA values) and back.
[[nodiscard]] std::optional<PcdEncoding> parse_pcd_encoding(std::string_view name);
[[nodiscard]] std::string_view to_string(PcdEncoding encoding);

/// True for names ending in .pcd, .ply or .bin, optionally followed by .gz (case-insensitive).
[[nodiscard]] bool is_point_cloud_file(const std::filesystem::path& path);

/// Reads any supported file, choosing the format from the name.
[[nodiscard]] Scan read_point_cloud(const std::filesystem::path& path);
[[nodiscard]] Scan read_pcd(const std::filesystem::path& path);
[[nodiscard]] Scan read_ply(const std::filesystem::path& path);
[[nodiscard]] Scan read_kitti_bin(const std::filesystem::path& path);

/// The same readers on the bytes of a file in memory (not gzip'd); `file` names them in errors.
[[nodiscard]] Scan parse_pcd(std::span<const unsigned char> bytes, const std::string& file);
[[nodiscard]] Scan parse_ply(std::span<const unsigned char> bytes, const std::string& file);
[[nodiscard]] Scan parse_kitti_bin(std::span<const unsigned char> bytes, const std::string& file);

/// Fields x y z [intensity] [t] float32 and [sensor_id] uint8, each written only if the scan has it.
void write_pcd(const std::filesystem::path& path, const Scan& scan, PcdEncoding encoding = PcdEncoding::Binary);
/// Binary little endian vertices: float x y z [intensity].
void write_ply(const std::filesystem::path& path, const std::vector<Vec3f>& points,
               const std::vector<float>* intensity = nullptr);
/// float32 x y z intensity per point (intensity 0 when the scan has none).
void write_kitti_bin(const std::filesystem::path& path, const Scan& scan);

}  // namespace farlio::io
