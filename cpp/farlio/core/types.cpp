#include "farlio/core/types.hpp"

#include <cmath>

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

std::size_t Scan::remove_non_finite() {
  std::size_t out = 0;
  const bool t = has_time(), in = !intensity.empty(), id = !sensor_id.empty();
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (!points[i].allFinite() || (t && !std::isfinite(time_s[i]))) continue;
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
