#include "farlio/core/types.hpp"

#include <bit>
#include <cmath>
#include <cstdint>

#include "farlio/core/error.hpp"

namespace farlio {

void Scan::validate(const std::string& what) const {
  const auto n = points.size();
  auto check = [&](std::size_t m, const char* field) {
    if (m != 0 && m != n) {
      throw InputError(what + ": field '" + field + "' has " + std::to_string(m) + " values for " + std::to_string(n) +
                       " points");
    }
  };
  check(time_s.size(), "time_s");
  check(intensity.size(), "intensity");
  check(sensor_id.size(), "sensor_id");
  if (end_stamp_ns < start_stamp_ns) {
    throw InputError(what + ": scan end stamp " + std::to_string(end_stamp_ns) + " ns is before its start stamp " +
                     std::to_string(start_stamp_ns) + " ns");
  }
}

namespace {

/// Whether none of the n floats is NaN or Inf: branch-free over the exponent bits, which the
/// compiler vectorises (std::isfinite per value is several times slower on a 100k-point scan).
bool floats_finite(const float* values, std::size_t n) {
  constexpr std::uint32_t kExponent = 0x7f800000u;  // all exponent bits set: Inf or NaN
  std::uint32_t bad = 0;
  for (std::size_t i = 0; i < n; ++i) {
    bad |= static_cast<std::uint32_t>((std::bit_cast<std::uint32_t>(values[i]) & kExponent) == kExponent);
  }
  return bad == 0;
}

}  // namespace

bool Scan::all_finite() const {
  static_assert(sizeof(Vec3f) == 3 * sizeof(float), "points are 3n contiguous floats");
  return points.empty() ||
         (floats_finite(points.data()->data(), 3 * points.size()) && floats_finite(time_s.data(), time_s.size()));
}

std::size_t Scan::remove_non_finite() {
  if (all_finite()) return 0;
  const bool t = has_time(), in = !intensity.empty(), id = !sensor_id.empty();
  const auto finite = [&](std::size_t i) {
    const Vec3f& p = points[i];
    return std::isfinite(p.x()) && std::isfinite(p.y()) && std::isfinite(p.z()) && (!t || std::isfinite(time_s[i]));
  };
  std::size_t out = 0;  // the points before the first non-finite one stay where they are
  while (out < points.size() && finite(out)) ++out;
  for (std::size_t i = out; i < points.size(); ++i) {
    if (!finite(i)) continue;
    points[out] = points[i];
    if (t) time_s[out] = time_s[i];
    if (in) intensity[out] = intensity[i];
    if (id) sensor_id[out] = sensor_id[i];
    ++out;
  }
  const std::size_t removed = points.size() - out;
  points.resize(out);
  if (t) time_s.resize(out);
  if (in) intensity.resize(out);
  if (id) sensor_id.resize(out);
  return removed;
}

}  // namespace farlio
