// Bindings of the LiDAR-inertial odometry replayed on a simulated clock, with its per-scan reports.
#include "farlio/pipeline/odometry.hpp"

#include <nanobind/eigen/dense.h>
#include <nanobind/stl/filesystem.h>
#include <nanobind/stl/optional.h>
#include <nanobind/stl/pair.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/tuple.h>
#include <nanobind/stl/vector.h>

#include <mutex>
#include <utility>
#include <vector>

#include "bindings.hpp"
#include "farlio/map/map_snapshot.hpp"
#include "locked.hpp"
#include "repr.hpp"

namespace nb = nanobind;
using namespace nb::literals;

namespace farlio::python {
namespace {

/// Odometry with its 10 ms output collected between calls (no Python callback on the hot path).
struct PyOdometry {
  std::mutex mutex;
  std::vector<pipeline::OdometrySample> pending;
  pipeline::Odometry odometry;
  PyOdometry(const Config& c, const SE3& T, double g, std::vector<ImuSample> imu, const pipeline::ReplayOptions& o)
      : odometry(c, T, g, std::move(imu), o) {
    odometry.on_odometry = [this](const pipeline::OdometrySample& s) { pending.push_back(s); };
  }
};

/// The replay's latency model.
void bind_replay_options(nb::module_& m) {
  nb::enum_<pipeline::LatencyModel>(m, "LatencyModel")
      .value("Measured", pipeline::LatencyModel::Measured)
      .value("Zero", pipeline::LatencyModel::Zero)
      .value("Fixed", pipeline::LatencyModel::Fixed);
  nb::class_<pipeline::ReplayOptions>(m, "ReplayOptions", "Latency model of the deterministic replay.")
      .def(nb::init<>())
      .def_rw("latency", &pipeline::ReplayOptions::latency)
      .def_rw("fixed_latency_s", &pipeline::ReplayOptions::fixed_latency_s)
      .def_rw("added_delay_s", &pipeline::ReplayOptions::added_delay_s);
}

/// How well a registration constrained the pose, and what happened to one scan.
void bind_odometry_frame(nb::module_& m) {
  nb::class_<registration::Degeneracy>(
      m, "Degeneracy", "How well a registration constrained the body pose (body frame, largest std first).")
      .def_ro("translation_std_m", &registration::Degeneracy::translation_std_m)
      .def_ro("translation_axes", &registration::Degeneracy::translation_axes, "principal directions as columns")
      .def_ro("rotation_std_rad", &registration::Degeneracy::rotation_std_rad)
      .def_ro("rotation_axes", &registration::Degeneracy::rotation_axes, "principal axes as columns")
      .def_ro("degenerate_translations", &registration::Degeneracy::degenerate_translations)
      .def_ro("degenerate_rotations", &registration::Degeneracy::degenerate_rotations)
      .def_prop_ro("degenerate", &registration::Degeneracy::degenerate)
      .def("__repr__", attribute_repr({"translation_std_m", "rotation_std_rad", "degenerate_translations",
                                       "degenerate_rotations"}));
  nb::class_<pipeline::OdometryFrame>(m, "OdometryFrame", "What happened to one scan in the LIO replay.")
      .def_ro("scan", &pipeline::OdometryFrame::scan)
      .def_ro("body_pose", &pipeline::OdometryFrame::body_pose)
      .def_ro("processed", &pipeline::OdometryFrame::processed)
      .def_ro("fused", &pipeline::OdometryFrame::fused)
      .def_ro("drop_reason", &pipeline::OdometryFrame::drop_reason)
      .def_ro("started_ns", &pipeline::OdometryFrame::started_ns)
      .def_ro("available_ns", &pipeline::OdometryFrame::available_ns)
      .def_ro("guess_from_fusion", &pipeline::OdometryFrame::guess_from_fusion)
      .def_ro("degeneracy", &pipeline::OdometryFrame::degeneracy, "Degeneracy of a registered scan, else None")
      .def_prop_ro(
          "registered_points", [](const pipeline::OdometryFrame& f) { return point_rows(f.registered_points); },
          "(N, 3) float32: the undistorted, downsampled scan in the world frame at the registered pose "
          "(OnlineOdometry with keep_registered_points; else empty)")
      .def("__repr__", attribute_repr({"processed", "fused", "drop_reason", "started_ns", "available_ns",
                                       "guess_from_fusion", "body_pose", "scan"}));
}

/// The fusion's initialisation and counters.
void bind_fusion_stats(nb::module_& m) {
  nb::class_<fusion::InitializationReport>(m, "InitializationReport",
                                           "How and when the filter was first initialised (fusion/initialization.hpp)")
      .def_ro("initialized", &fusion::InitializationReport::initialized)
      .def_ro("mode", &fusion::InitializationReport::mode, "'standstill' or 'in motion' ('' before)")
      .def_ro("stamp_ns", &fusion::InitializationReport::stamp_ns, "the LiDAR result that initialised it")
      .def_ro("window_poses", &fusion::InitializationReport::window_poses, "LiDAR poses aligned with the IMU")
      .def_ro("window_s", &fusion::InitializationReport::window_s, "their time span")
      .def_ro("speed_m_s", &fusion::InitializationReport::speed_m_s, "the speed found")
      .def_ro("up_map", &fusion::InitializationReport::up_map, "the up direction (against gravity) in the map frame")
      .def_ro("map_tilt_deg", &fusion::InitializationReport::map_tilt_deg,
              "angle between the map frame's z axis and up (0: the map frame is level)")
      .def_ro("gravity_norm_error", &fusion::InitializationReport::gravity_norm_error,
              "| |g| estimated freely - g | / g over the window: how consistent its data were")
      .def("__repr__", attribute_repr({"mode", "stamp_ns", "window_poses", "window_s", "speed_m_s", "map_tilt_deg",
                                       "gravity_norm_error"}));
  nb::class_<fusion::InnovationStats>(m, "InnovationStats",
                                      "The normalised innovations (NIS) of a LiDAR group (fusion/innovation_stats.hpp)")
      .def_ro("group", &fusion::InnovationStats::group, "the measurement group: pose, position, orientation, velocity")
      .def_ro("dim", &fusion::InnovationStats::dim, "its degrees of freedom")
      .def_ro("count", &fusion::InnovationStats::count, "groups checked (accepted or gated)")
      .def_prop_ro("mean_per_dof", &fusion::InnovationStats::mean_per_dof,
                   "mean NIS per degree of freedom: 1 when the filter's noise fits the data")
      .def_prop_ro("share_beyond_95", &fusion::InnovationStats::share_beyond_95,
                   "share of groups beyond the chi-squared 95 % quantile: 0.05 when it fits")
      .def("__repr__", attribute_repr({"group", "dim", "count", "mean_per_dof", "share_beyond_95"}));
  nb::class_<fusion::FusionStats>(m, "FusionStats")
      .def_ro("steps", &fusion::FusionStats::steps)
      .def_ro("lidar_groups_accepted", &fusion::FusionStats::lidar_groups_accepted)
      .def_ro("lidar_groups_rejected", &fusion::FusionStats::lidar_groups_rejected)
      .def_ro("reinitializations", &fusion::FusionStats::reinitializations)
      .def_ro("initialization", &fusion::FusionStats::initialization)
      .def_ro("up_map", &fusion::FusionStats::up_map,
              "the up direction (against gravity) in the map frame as the filter now estimates it")
      .def_ro("imu_gaps", &fusion::FusionStats::imu_gaps)
      .def_ro("imu_samples_dropped", &fusion::FusionStats::imu_samples_dropped)
      .def_ro("imu_samples_rejected", &fusion::FusionStats::imu_samples_rejected,
              "IMU samples rejected by the gate (non-finite, impossible, spikes)")
      .def_ro("accel_in_g", &fusion::FusionStats::accel_in_g)
      .def_ro("accel_unit_message", &fusion::FusionStats::accel_unit_message)
      .def_ro("gyro_bias_rad_s", &fusion::FusionStats::gyro_bias_rad_s)
      .def_ro("accel_bias_m_s2", &fusion::FusionStats::accel_bias_m_s2)
      .def_ro("last_warning", &fusion::FusionStats::last_warning)
      .def_ro("measured_gyro_step_std_rad_s", &fusion::FusionStats::measured_gyro_step_std_rad_s,
              "the gyro's noise measured on its samples, averaged over a filter step (0 before the first estimate)")
      .def_ro("measured_accel_step_std_m_s2", &fusion::FusionStats::measured_accel_step_std_m_s2,
              "the accelerometer's noise measured on its samples, averaged over a filter step")
      .def_ro("imu_rate_hz", &fusion::FusionStats::imu_rate_hz, "the IMU's sample rate (0 before the first estimate)")
      .def_ro("deskew_gyro_weight", &fusion::FusionStats::deskew_gyro_weight,
              "the gyro's mean weight in the rotation rate that undistorts the scans, per LiDAR axis "
              "(1: the gyro's rate, 0: the LiDAR's constant twist)")
      .def_ro("lidar_innovation", &fusion::FusionStats::lidar_innovation,
              "the LiDAR groups' normalised innovations, one InnovationStats per group fused")
      .def("__repr__", attribute_repr({"steps", "lidar_groups_accepted", "lidar_groups_rejected", "reinitializations",
                                       "imu_gaps", "imu_samples_dropped", "imu_samples_rejected", "accel_in_g",
                                       "gyro_bias_rad_s", "last_warning"}));
}

/// Odometry's constructor and the calls of a run: scans in, odometry out, the start pose and a prior map.
nb::class_<PyOdometry> bind_odometry_run(nb::module_& m) {
  return nb::class_<PyOdometry>(
             m, "Odometry",
             "LiDAR-inertial odometry replayed on a simulated clock (LiDAR-only without IMU). Calls from "
             "several threads run one at a time (scans must still come in time order).")
      .def(nb::init<const Config&, const SE3&, double, std::vector<ImuSample>, const pipeline::ReplayOptions&>(),
           "config"_a, "T_imu_lidar"_a, "gravity_m_s2"_a, "imu"_a, "options"_a = pipeline::ReplayOptions())
      .def(
          "process",
          [](PyOdometry& o, const Scan& s) { return locked(o, [&](PyOdometry& x) { return x.odometry.process(s); }); },
          "scan"_a, nb::call_guard<nb::gil_scoped_release>())
      .def(
          "finish", [](PyOdometry& o, std::int64_t t) { locked(o, [&](PyOdometry& x) { x.odometry.finish(t); }); },
          "stamp_ns"_a, nb::call_guard<nb::gil_scoped_release>())
      .def(
          "take_odometry",
          [](PyOdometry& o) {
            return locked(o, [](PyOdometry& x) {
              std::vector<std::pair<std::int64_t, SE3>> out;
              for (const auto& s : x.pending) out.emplace_back(s.stamp_ns, s.body_pose);
              x.pending.clear();
              return out;
            });
          },
          nb::call_guard<nb::gil_scoped_release>(),
          "[(stamp_ns, body pose)] of the 10 ms odometry output since the last call.")
      .def(
          "set_initial_pose",
          [](PyOdometry& o, const SE3& pose) { locked(o, [&](PyOdometry& x) { x.odometry.set_initial_pose(pose); }); },
          "body_pose"_a, nb::call_guard<nb::gil_scoped_release>(),
          "The body pose at the first scan in the world (the prior map's frame): position and yaw as given; roll "
          "and pitch too when LiDAR-only, from gravity when inertial. Before the first scan.")
      .def(
          "set_prior_map",
          [](PyOdometry& o, const Scan& map) {
            locked(o, [&](PyOdometry& x) { x.odometry.set_prior_map(map.points); });
          },
          "map"_a, nb::call_guard<nb::gil_scoped_release>(),
          "Localization: the submap is built from the points of `map` (world frame) and held fixed. Before the "
          "first scan.");
}

/// What Odometry holds: its state, warnings, the fusion's counters, the submap and the backend.
void bind_odometry_state(nb::class_<PyOdometry>& c) {
  c.def_prop_ro(
       "localizing",
       [](PyOdometry& o) { return locked(o, [](PyOdometry& x) { return x.odometry.scan_pipeline().localizing(); }); })
      .def_prop_ro("inertial",
                   [](PyOdometry& o) { return locked(o, [](PyOdometry& x) { return x.odometry.inertial(); }); })
      .def(
          "take_warnings",
          [](PyOdometry& o) { return locked(o, [](PyOdometry& x) { return x.odometry.take_warnings(); }); },
          nb::call_guard<nb::gil_scoped_release>(),
          "What was tolerated since the last call (sorted IMU, an unusable IMU, a reset of the fusion).")
      .def_prop_ro(
          "effective_config",
          [](PyOdometry& o) { return locked(o, [](PyOdometry& x) { return x.odometry.scan_pipeline().config(); }); },
          "The parameters in use (the voxel size is fixed at the first scan when auto).")
      .def_prop_ro("fusion_stats",
                   [](PyOdometry& o) { return locked(o, [](PyOdometry& x) { return x.odometry.fusion_stats(); }); })
      .def_prop_ro(
          "initial_body_pose",
          [](PyOdometry& o) { return locked(o, [](PyOdometry& x) { return x.odometry.initial_body_pose(); }); })
      .def(
          "map_points",
          [](PyOdometry& o) {
            const map::MapSnapshot snapshot = [&] {
              nb::gil_scoped_release unlocked;
              return locked(o, [](PyOdometry& x) { return x.odometry.scan_pipeline().backend().map_snapshot(); });
            }();
            return map_points(snapshot);
          },
          "(N, 3) float32 copy of the submap's points (world frame)")
      .def_prop_ro("map_memory_bytes",
                   [](PyOdometry& o) {
                     return locked(o,
                                   [](PyOdometry& x) { return x.odometry.scan_pipeline().backend().memory_bytes(); });
                   })
      .def_prop_ro(
          "device",
          [](PyOdometry& o) {
            return device_name(locked(o, [](PyOdometry& x) { return x.odometry.scan_pipeline().backend().device(); }));
          },
          "'cpu' or 'cuda': the backend the scan pipeline runs on")
      .def_prop_ro(
          "device_message",
          [](PyOdometry& o) {
            return locked(o, [](PyOdometry& x) { return x.odometry.scan_pipeline().device_message(); });
          },
          "why device auto fell back to the CPU ('' when it did not)");
}

}  // namespace

/// LatencyModel, ReplayOptions, Degeneracy, OdometryFrame, InitializationReport, FusionStats, Odometry.
void bind_odometry(nb::module_& m) {
  bind_replay_options(m);
  bind_odometry_frame(m);
  bind_fusion_stats(m);
  auto odometry = bind_odometry_run(m);
  bind_odometry_state(odometry);
}

}  // namespace farlio::python
