// Bindings of the stage limits: the machine's yardsticks and the time a frame's work implies at them.
#include "farlio/pipeline/stage_limits.hpp"

#include <nanobind/eigen/dense.h>
#include <nanobind/stl/filesystem.h>
#include <nanobind/stl/optional.h>
#include <nanobind/stl/pair.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/tuple.h>
#include <nanobind/stl/vector.h>

#include "bindings.hpp"
#include "farlio/exec/cpu_executor.hpp"
#include "repr.hpp"

namespace nb = nanobind;
using namespace nb::literals;

namespace farlio::python {

/// Yardsticks, measure_yardsticks, stage_limits.
void bind_stage_limits(nb::module_& m) {
  nb::class_<pipeline::Yardsticks>(m, "Yardsticks", "The machine's rates the stage limits are measured against.")
      .def_ro("threads", &pipeline::Yardsticks::threads)
      .def_ro("memory_read_bytes_per_s", &pipeline::Yardsticks::memory_read_bytes_per_s,
              "streaming read far beyond the caches")
      .def_ro("l1_distances_per_s", &pipeline::Yardsticks::l1_distances_per_s,
              "point-query squared distances over points held in L1 (8 flops each)")
      .def("__repr__", attribute_repr({"threads", "memory_read_bytes_per_s", "l1_distances_per_s"}));
  m.def(
      "measure_yardsticks",
      [](int threads, int rounds) {
        exec::CpuExecutor executor(threads);
        return pipeline::measure_yardsticks(executor, rounds);
      },
      "threads"_a = 0, "rounds"_a = 3, nb::call_guard<nb::gil_scoped_release>(),
      "memory read bandwidth and L1 distance rate on `threads` threads (0: all), the best of `rounds` "
      "(about 0.1 s each)");
  m.def("stage_limits", &pipeline::stage_limits, "frame"_a, "k"_a, "yardsticks"_a,
        "the limits of one frame's stages as FrameTimings: the time each stage's unavoidable work takes at the "
        "yardsticks' rates (docs/performance.md); k is map.covariance_neighbors");
}

}  // namespace farlio::python
