// Bindings of the LIO for live data: IMU samples and scans pushed in, odometry and frames polled.
#include "farlio/pipeline/online_odometry.hpp"

#include <nanobind/eigen/dense.h>
#include <nanobind/stl/filesystem.h>
#include <nanobind/stl/optional.h>
#include <nanobind/stl/pair.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/tuple.h>
#include <nanobind/stl/vector.h>

#include <chrono>
#include <condition_variable>
#include <mutex>
#include <utility>
#include <vector>

#include "bindings.hpp"
#include "repr.hpp"

namespace nb = nanobind;
using namespace nb::literals;

namespace farlio::python {
namespace {

/// The online odometry with its outputs collected for polling: the worker thread never calls
/// into Python (and so never needs the GIL).
struct PyOnlineOdometry {
  std::mutex mutex;
  std::condition_variable frame_ready;
  std::vector<pipeline::OdometrySample> samples;
  std::vector<pipeline::OdometryFrame> frames;
  pipeline::OnlineOdometry odometry;
  PyOnlineOdometry(const Config& c, const SE3& T, double g, bool keep_registered_points)
      : odometry(
            c, T, g,
            [this](const pipeline::OdometrySample& s) {
              std::lock_guard lock(mutex);
              samples.push_back(s);
            },
            [this](const pipeline::OdometryFrame& f) {
              {
                std::lock_guard lock(mutex);
                frames.push_back(f);
              }
              frame_ready.notify_all();
            },
            keep_registered_points) {}
  ~PyOnlineOdometry() { odometry.stop(); }  // before the vectors the callbacks fill go away
  /// Empties one of the collected vectors and returns its contents.
  template <typename T>
  std::vector<T> take(std::vector<T>& collected) {
    std::lock_guard lock(mutex);
    return std::exchange(collected, {});
  }
  /// The frames collected so far, waiting up to timeout_s for one when there are none.
  std::vector<pipeline::OdometryFrame> wait_frames(double timeout_s) {
    std::unique_lock lock(mutex);
    frame_ready.wait_for(lock, std::chrono::duration<double>(timeout_s), [this] { return !frames.empty(); });
    return std::exchange(frames, {});
  }
};

}  // namespace

/// OdometrySample and OnlineOdometry.
void bind_online_odometry(nb::module_& m) {
  nb::class_<pipeline::OdometrySample>(m, "OdometrySample", "One 10 ms sample of the fused odometry.")
      .def_ro("stamp_ns", &pipeline::OdometrySample::stamp_ns)
      .def_ro("body_pose", &pipeline::OdometrySample::body_pose)
      .def_ro("velocity_body_m_s", &pipeline::OdometrySample::velocity_body_m_s)
      .def("__repr__", attribute_repr({"stamp_ns", "body_pose", "velocity_body_m_s"}));
  nb::class_<PyOnlineOdometry>(m, "OnlineOdometry",
                               "LIO for live data: push IMU samples and scans as they arrive (any thread); the scan "
                               "pipeline runs on a worker; poll the 100 Hz odometry and the per-scan frames.")
      .def(nb::init<const Config&, const SE3&, double, bool>(), "config"_a, "T_imu_lidar"_a, "gravity_m_s2"_a = 9.81,
           "keep_registered_points"_a = false)
      .def(
          "add_imu", [](PyOnlineOdometry& o, const ImuSample& s) { o.odometry.add_imu(s); }, "sample"_a,
          nb::call_guard<nb::gil_scoped_release>())
      .def(
          "add_scan",
          [](PyOnlineOdometry& o, Scan& s, bool consume) {
            return consume ? o.odometry.add_scan(std::move(s)) : o.odometry.add_scan(s);
          },
          "scan"_a, nb::kw_only(), "consume"_a = false, nb::call_guard<nb::gil_scoped_release>(),
          "False when dropped at once because the worker was busy (registration.max_wait_periods 0). Otherwise "
          "a scan waits for a busy worker up to max_wait_periods; a newer scan takes the place of one that waits, "
          "and one that waited longer is dropped when the worker comes to it (both reported as dropped frames). "
          "consume=True moves the scan's arrays in instead of copying them (the scan is left empty).")
      .def(
          "wait_idle", [](PyOnlineOdometry& o) { o.odometry.wait_idle(); }, nb::call_guard<nb::gil_scoped_release>(),
          "Blocks until every scan handed over is processed.")
      .def(
          "stop", [](PyOnlineOdometry& o) { o.odometry.stop(); }, nb::call_guard<nb::gil_scoped_release>())
      .def(
          "take_odometry", [](PyOnlineOdometry& o) { return o.take(o.samples); },
          "The 10 ms odometry samples since the last call.")
      .def(
          "take_frames", [](PyOnlineOdometry& o) { return o.take(o.frames); },
          "What happened to each scan since the last call (processed or dropped, pose, timings).")
      .def("wait_frames", &PyOnlineOdometry::wait_frames, "timeout_s"_a, nb::call_guard<nb::gil_scoped_release>(),
           "As take_frames, but waits up to timeout_s for a frame when there is none yet.")
      .def(
          "map_points", [](const PyOnlineOdometry& o) { return map_points(o.odometry.map_snapshot()); },
          nb::call_guard<nb::gil_scoped_release>(),
          "(N, 3) float32 copy of the submap's points (world frame); waits for the scan in progress")
      .def(
          "set_initial_pose", [](PyOnlineOdometry& o, const SE3& pose) { o.odometry.set_initial_pose(pose); },
          "body_pose"_a, "As Odometry.set_initial_pose; before the first scan.")
      .def(
          "set_prior_map", [](PyOnlineOdometry& o, const Scan& map) { o.odometry.set_prior_map(map.points); }, "map"_a,
          nb::call_guard<nb::gil_scoped_release>(), "As Odometry.set_prior_map; before the first scan.")
      .def_prop_ro("inertial", [](PyOnlineOdometry& o) { return o.odometry.inertial(); })
      .def(
          "take_warnings", [](PyOnlineOdometry& o) { return o.odometry.take_warnings(); },
          "The warnings since the last call (a reset of the fusion, the gyro's unit, an unusable IMU).")
      .def_prop_ro(
          "device", [](PyOnlineOdometry& o) { return device_name(o.odometry.device()); },
          "'cpu' or 'cuda': the backend the scan pipeline runs on")
      .def_prop_ro(
          "device_message", [](PyOnlineOdometry& o) { return o.odometry.device_message(); },
          "why device auto fell back to the CPU ('' when it did not)")
      .def_prop_ro(
          "fusion_stats", [](PyOnlineOdometry& o) { return o.odometry.fusion_stats(); },
          "The fusion's counters and gyro bias (None before the first scan or LiDAR-only).")
      .def_prop_ro("scans_dropped_busy", [](PyOnlineOdometry& o) { return o.odometry.scans_dropped_busy(); });
}

}  // namespace farlio::python
