#include "farlio/io/point_times.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "farlio/core/error.hpp"

namespace farlio::io {

bool point_time_span_plausible(double span_s) { return std::isfinite(span_s) && span_s <= kMaxScanSpan_s; }

std::string point_time_problem(std::span<const float> time_s, double duration_s) {
  double lo = std::numeric_limits<double>::infinity();
  double hi = -lo;
  for (const float t : time_s) {
    if (!std::isfinite(t)) continue;
    lo = std::min(lo, static_cast<double>(t));
    hi = std::max(hi, static_cast<double>(t));
  }
  if (lo > hi) return {};  // no finite time
  std::ostringstream out;
  if (!point_time_span_plausible(hi - lo)) {
    out << "per-point times span " << hi - lo << " s (" << lo << " to " << hi << " s), longer than a scan can last ("
        << kMaxScanSpan_s << " s): their unit is not seconds (nanoseconds or microseconds stored as seconds?)";
    return out.str();
  }
  const double tolerance = std::max(kPointTimeToleranceMin_s, kPointTimeToleranceFraction * std::max(duration_s, 0.0));
  if (lo < -tolerance) {
    out << "per-point times start at " << lo
        << " s, before the scan start: they must be seconds since the scan start (>= 0), not relative to its end";
    return out.str();
  }
  if (duration_s > 0 && hi > duration_s + tolerance) {
    out << "per-point times reach " << hi << " s but the scan lasts " << duration_s << " s (" << hi / duration_s
        << " times as long; its start and end stamps): times in another unit, absolute times, or a wrong scan period?";
    return out.str();
  }
  return {};
}

void check_point_times(const Scan& scan, const std::string& what) {
  const std::string problem = point_time_problem(scan.time_s, scan.duration_s());
  if (!problem.empty()) throw InputError(what + ": " + problem);
}

}  // namespace farlio::io
