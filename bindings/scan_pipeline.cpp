// Bindings of the scan pipeline: preprocess, registration against the submap, map update.
#include "farlio/pipeline/scan_pipeline.hpp"

#include <nanobind/eigen/dense.h>
#include <nanobind/stl/filesystem.h>
#include <nanobind/stl/optional.h>
#include <nanobind/stl/pair.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/tuple.h>
#include <nanobind/stl/vector.h>

#include <mutex>
#include <optional>

#include "bindings.hpp"
#include "farlio/map/map_snapshot.hpp"
#include "locked.hpp"

namespace nb = nanobind;
using namespace nb::literals;

namespace farlio::python {
namespace {

/// A scan pipeline and the mutex its calls take.
struct PyScanPipeline {
  std::mutex mutex;
  pipeline::ScanPipeline pipeline;
  /// The scans last staged: alive while the backend may still read them (the GIL guards these).
  nb::object staged[2];
  PyScanPipeline(const Config& c, const SE3& initial_pose) : pipeline(c, initial_pose) {}
};

}  // namespace

/// ScanPipeline.
void bind_scan_pipeline(nb::module_& m) {
  nb::class_<PyScanPipeline>(m, "ScanPipeline",
                             "preprocess -> sparsity-aware GICP against the adaptive submap -> map update. Calls from "
                             "several threads run one at a time (scans must still come in time order).")
      .def(nb::init<const Config&, const SE3&>(), "config"_a = Config(), "initial_pose"_a = SE3())
      .def(
          "process",
          [](PyScanPipeline& p, const Scan& scan, const std::optional<SE3>& guess) {
            return locked(p, [&](PyScanPipeline& x) { return x.pipeline.process(scan, guess); });
          },
          "scan"_a, "initial_guess"_a = nb::none(), nb::call_guard<nb::gil_scoped_release>(),
          "Registers one scan; without a guess the constant-velocity model supplies one. Points with NaN or Inf "
          "coordinates or times are dropped (FrameResult.non_finite_points).")
      .def(
          "stage_next",
          [](PyScanPipeline& p, nb::handle scan) {
            const Scan& s = nb::cast<const Scan&>(scan);
            p.staged[0] = std::move(p.staged[1]);
            p.staged[1] = nb::borrow(scan);
            locked(p, [&](PyScanPipeline& x) { x.pipeline.stage_next(s); });
          },
          "scan"_a,
          "Offline, scans back to back: the scan after the one about to be processed, so that the CUDA backend "
          "uploads it while it works (the CPU backend has nothing to move). Process that same object, unchanged; any "
          "other scan is uploaded in its own frame. The results are the same.")
      .def_prop_ro("frames",
                   [](PyScanPipeline& p) { return locked(p, [](PyScanPipeline& x) { return x.pipeline.frames(); }); })
      .def(
          "map_points",
          [](PyScanPipeline& p) {
            const map::MapSnapshot snapshot = [&] {
              nb::gil_scoped_release unlocked;
              return locked(p, [](PyScanPipeline& x) { return x.pipeline.backend().map_snapshot(); });
            }();
            return map_points(snapshot);
          },
          "(N, 3) float32 copy of the submap's points (world frame)")
      .def_prop_ro("map_memory_bytes",
                   [](PyScanPipeline& p) {
                     return locked(p, [](PyScanPipeline& x) { return x.pipeline.backend().memory_bytes(); });
                   })
      .def_prop_ro(
          "device",
          [](PyScanPipeline& p) {
            return device_name(locked(p, [](PyScanPipeline& x) { return x.pipeline.backend().device(); }));
          },
          "'cpu' or 'cuda': the backend the stages run on")
      .def_prop_ro(
          "device_message",
          [](PyScanPipeline& p) { return locked(p, [](PyScanPipeline& x) { return x.pipeline.device_message(); }); },
          "why device auto fell back to the CPU ('' when it did not)");
}

}  // namespace farlio::python
