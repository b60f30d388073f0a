#include "farlio/core/clock_check.hpp"

#include <array>
#include <utility>

#include "farlio/core/time.hpp"

namespace farlio {
namespace {

struct Span {
  double first_s, last_s;
  [[nodiscard]] Span scaled(double f) const { return {first_s * f, last_s * f}; }
  [[nodiscard]] bool overlaps(const Span& o, double tolerance_s) const {
    return first_s <= o.last_s + tolerance_s && o.first_s <= last_s + tolerance_s;
  }
  [[nodiscard]] std::string text() const {
    return first_s == last_s ? seconds_text(first_s) + " s"
                             : "[" + seconds_text(first_s) + ", " + seconds_text(last_s) + "] s";
  }
};

Span seconds_of(const StampSpan& s) { return {ns_to_seconds(s.first_ns), ns_to_seconds(s.last_ns)}; }

/// Stamps read as ns that were written in another unit are off by these factors.
constexpr std::array<std::pair<double, const char*>, 3> kOtherUnits{{{1e3, "us"}, {1e6, "ms"}, {1e9, "s"}}};

/// Which unit mistake would make the spans overlap ('' if none).
std::string unit_hint(const Span& imu, const Span& scans, double tolerance_s) {
  for (const auto& [factor, unit] : kOtherUnits) {
    if (imu.scaled(factor).overlaps(scans, tolerance_s)) {
      return std::string("; read as ") + unit +
             " instead of ns the IMU stamps would overlap the scans: is imu.csv (or "
             "the IMU topic) stamped in " +
             unit + "?";
    }
    if (scans.scaled(factor).overlaps(imu, tolerance_s)) {
      return std::string("; read as ") + unit +
             " instead of ns the scan stamps would overlap the IMU: are the scans "
             "(file names, times.txt, header stamps) stamped in " +
             unit + "?";
    }
  }
  return "; is there an offset between the IMU and LiDAR clocks, or are the units not the same?";
}

}  // namespace

ClockCheck check_clocks(const StampSpan& imu_ns, const StampSpan& scans_ns, double tolerance_s) {
  ClockCheck out;
  const Span imu = seconds_of(imu_ns), scans = seconds_of(scans_ns);
  const std::string scans_text = (scans.first_s == scans.last_s ? "the scan ends at " : "scans span ") + scans.text();
  if (!imu.overlaps(scans, tolerance_s)) {
    out.error = "IMU stamps span " + imu.text() + ", " + scans_text + ": they do not overlap" +
                unit_hint(imu, scans, tolerance_s);
    return out;
  }
  const double late_s = imu.first_s - scans.first_s;
  if (late_s > tolerance_s) {
    out.warnings.push_back("the IMU starts " + seconds_text(late_s) + " s after the first scan (IMU stamps span " +
                           imu.text() + ", " + scans_text +
                           "): the scans before it run LiDAR-only; an offset between the IMU and LiDAR clocks?");
  }
  const double early_s = scans.last_s - imu.last_s;
  if (early_s > tolerance_s) {
    out.warnings.push_back("the IMU ends " + seconds_text(early_s) + " s before the last scan (IMU stamps span " +
                           imu.text() + ", " + scans_text +
                           "): the fusion stops there; an offset between the IMU and LiDAR clocks?");
  }
  return out;
}

}  // namespace farlio
