#include "farlio/io/point_cloud_io.hpp"

#include <algorithm>
#include <cctype>
#include <string>

#include "farlio/core/error.hpp"

namespace farlio::io {
namespace {

enum class CloudFormat { Pcd, Ply, KittiBin };

std::string lowercase_name(const std::filesystem::path& path) {
  std::string name = path.filename().string();
  std::transform(name.begin(), name.end(), name.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return name;
}

bool ends_with(const std::string& s, std::string_view suffix) {
  return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

std::optional<CloudFormat> format_of(const std::filesystem::path& path) {
  std::string name = lowercase_name(path);
  constexpr std::string_view kGzip = ".gz";
  if (ends_with(name, kGzip)) name.resize(name.size() - kGzip.size());
  if (ends_with(name, ".pcd")) return CloudFormat::Pcd;
  if (ends_with(name, ".ply")) return CloudFormat::Ply;
  if (ends_with(name, ".bin")) return CloudFormat::KittiBin;
  return std::nullopt;
}

}  // namespace

std::optional<PcdEncoding> parse_pcd_encoding(std::string_view name) {
  if (name == "ascii") return PcdEncoding::Ascii;
  if (name == "binary") return PcdEncoding::Binary;
  if (name == "binary_compressed") return PcdEncoding::BinaryCompressed;
  return std::nullopt;
}

std::string_view to_string(PcdEncoding encoding) {
  switch (encoding) {
    case PcdEncoding::Ascii: return "ascii";
    case PcdEncoding::Binary: return "binary";
    case PcdEncoding::BinaryCompressed: return "binary_compressed";
  }
  return "binary";
}

bool is_point_cloud_file(const std::filesystem::path& path) { return format_of(path).has_value(); }

Scan read_point_cloud(const std::filesystem::path& path) {
  const auto format = format_of(path);
  if (!format) {
    throw InputError(path.string() + ": unknown point cloud file type (expected .pcd, .ply or .bin, optionally .gz)");
  }
  switch (*format) {
    case CloudFormat::Pcd: return read_pcd(path);
    case CloudFormat::Ply: return read_ply(path);
    case CloudFormat::KittiBin: return read_kitti_bin(path);
  }
  return {};
}

}  // namespace farlio::io
