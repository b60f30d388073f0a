#include "farlio/io/scalar.hpp"

#include <algorithm>
#include <bit>
#include <cstdint>
#include <cstring>
#include <map>

namespace farlio::io {
namespace {

template <class T>
T load_as(const unsigned char* p, bool big_endian) {
  unsigned char buf[sizeof(T)];
  std::memcpy(buf, p, sizeof(T));
  if (big_endian != (std::endian::native == std::endian::big)) std::reverse(buf, buf + sizeof(T));
  T v;
  std::memcpy(&v, buf, sizeof(T));
  return v;
}

}  // namespace

bool ScalarType::is_valid() const {
  if (kind == ScalarKind::Float) return size_bytes == 4 || size_bytes == 8;
  return size_bytes == 1 || size_bytes == 2 || size_bytes == 4 || size_bytes == 8;
}

std::optional<ScalarType> ply_scalar_type(const std::string& name) {
  static const std::map<std::string, ScalarType, std::less<>> kTypes = {
      {"char", {ScalarKind::Int, 1}},      {"int8", {ScalarKind::Int, 1}},      {"uchar", {ScalarKind::Uint, 1}},
      {"uint8", {ScalarKind::Uint, 1}},    {"short", {ScalarKind::Int, 2}},     {"int16", {ScalarKind::Int, 2}},
      {"ushort", {ScalarKind::Uint, 2}},   {"uint16", {ScalarKind::Uint, 2}},   {"int", {ScalarKind::Int, 4}},
      {"int32", {ScalarKind::Int, 4}},     {"uint", {ScalarKind::Uint, 4}},     {"uint32", {ScalarKind::Uint, 4}},
      {"float", {ScalarKind::Float, 4}},   {"float32", {ScalarKind::Float, 4}}, {"double", {ScalarKind::Float, 8}},
      {"float64", {ScalarKind::Float, 8}},
  };
  const auto it = kTypes.find(name);
  if (it == kTypes.end()) return std::nullopt;
  return it->second;
}

double load_scalar(const unsigned char* p, ScalarType type, bool big_endian) {
  switch (type.kind) {
    case ScalarKind::Float:
      return type.size_bytes == 4 ? static_cast<double>(load_as<float>(p, big_endian)) : load_as<double>(p, big_endian);
    case ScalarKind::Int:
      switch (type.size_bytes) {
        case 1: return load_as<std::int8_t>(p, big_endian);
        case 2: return load_as<std::int16_t>(p, big_endian);
        case 4: return load_as<std::int32_t>(p, big_endian);
        default: return static_cast<double>(load_as<std::int64_t>(p, big_endian));
      }
    case ScalarKind::Uint:
      switch (type.size_bytes) {
        case 1: return load_as<std::uint8_t>(p, big_endian);
        case 2: return load_as<std::uint16_t>(p, big_endian);
        case 4: return load_as<std::uint32_t>(p, big_endian);
        default: return static_cast<double>(load_as<std::uint64_t>(p, big_endian));
      }
  }
  return 0.0;
}

}  // namespace farlio::io
