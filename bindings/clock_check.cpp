// Bindings of the check that the IMU and the scans share a clock.
#include "farlio/core/clock_check.hpp"

#include <nanobind/eigen/dense.h>
#include <nanobind/stl/filesystem.h>
#include <nanobind/stl/optional.h>
#include <nanobind/stl/pair.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/tuple.h>
#include <nanobind/stl/vector.h>

#include "bindings.hpp"

namespace nb = nanobind;
using namespace nb::literals;

namespace farlio::python {

/// ClockCheck and check_clocks.
void bind_clock_check(nb::module_& m) {
  nb::class_<ClockCheck>(m, "ClockCheck", "Whether the IMU and the scans share a clock (check_clocks).")
      .def_ro("error", &ClockCheck::error, "empty when the spans overlap, else what was found")
      .def_ro("warnings", &ClockCheck::warnings);
  m.def(
      "check_clocks",
      [](std::int64_t imu_first_ns, std::int64_t imu_last_ns, std::int64_t scan_first_ns, std::int64_t scan_last_ns,
         double tolerance_s) {
        return check_clocks({imu_first_ns, imu_last_ns}, {scan_first_ns, scan_last_ns}, tolerance_s);
      },
      "imu_first_ns"_a, "imu_last_ns"_a, "scan_first_ns"_a, "scan_last_ns"_a, "tolerance_s"_a,
      "Compares the IMU's stamp span with the scans': an error when they do not overlap (naming the unit that "
      "would make them), warnings when the IMU starts late or ends early by more than tolerance_s.");
}

}  // namespace farlio::python
