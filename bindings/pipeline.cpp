// Bindings of the parameter set and the scan pipeline.
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

#include "bindings.hpp"
#include "farlio/core/clock_check.hpp"
#include "farlio/core/config_fields.hpp"
#include "farlio/io/point_stream_writer.hpp"
#include "farlio/pipeline/map_export.hpp"
#include "farlio/pipeline/odometry.hpp"
#include "farlio/pipeline/online_odometry.hpp"
#include "farlio/pipeline/pairwise.hpp"
#include "farlio/pipeline/scan_pipeline.hpp"
#include "farlio/pipeline/stage_limits.hpp"
#include "repr.hpp"

namespace nb = nanobind;
using namespace nb::literals;

namespace farlio::python {
namespace {

// Thread-safety of the bound classes (docs/hardening.md): the methods that release the GIL work on
// state no other call may touch meanwhile, so Odometry, ScanPipeline and MapExport hold a mutex
// of their own in every method; it is taken after the GIL is released (a thread waiting for it
// never blocks Python) and nothing called under it needs the GIL. OnlineOdometry is thread-safe
// itself. The other classes keep the GIL in every method.

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

/// A scan pipeline and the mutex its calls take.
struct PyScanPipeline {
  std::mutex mutex;
  pipeline::ScanPipeline pipeline;
  PyScanPipeline(const Config& c, const SE3& initial_pose) : pipeline(c, initial_pose) {}
};

/// A map export and the mutex its calls take.
struct PyMapExport {
  std::mutex mutex;
  pipeline::MapExport map;
  PyMapExport(double resolution_m, const Config& config, const std::string& spill_dir)
      : map(resolution_m, config.preprocess, config.num_threads, spill_dir, config.map.export_tile_m) {}
};

/// Calls f(object) holding the object's mutex.
template <typename T, typename F>
auto locked(T& o, F&& f) {
  std::lock_guard lock(o.mutex);
  return f(o);
}

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

/// A config value as a Python object (the device as its name).
nb::object to_python(const ConfigValue& value) {
  return std::visit(
      [](auto v) -> nb::object {
        if constexpr (std::is_same_v<decltype(v), Device>) {
          return nb::str(device_name(v));
        } else {
          return nb::cast(v);
        }
      },
      value);
}

/// The text form set_config_field parses: bools as true/false, anything else as str() gives it
/// (Python's float text reads back to the same double).
std::string text_of(nb::handle value) {
  if (nb::isinstance<nb::bool_>(value)) return nb::cast<bool>(value) ? "true" : "false";
  return nb::cast<std::string>(nb::str(value));
}

/// (N, 3) float32 rows, as numpy wants them.
using PointRows = Eigen::Matrix<float, Eigen::Dynamic, 3, Eigen::RowMajor>;

PointRows point_rows(const std::vector<Eigen::Vector3f>& pts) {
  PointRows out(static_cast<Eigen::Index>(pts.size()), 3);
  for (std::size_t i = 0; i < pts.size(); ++i) out.row(static_cast<Eigen::Index>(i)) = pts[i].transpose();
  return out;
}

PointRows map_points(const map::MapSnapshot& snapshot) {
  std::vector<Eigen::Vector3f> pts;
  snapshot.for_each_point([&](const Eigen::Vector3f& x, const map::Cov3&, bool) { pts.push_back(x); });
  return point_rows(pts);
}

}  // namespace

void bind_pipeline(nb::module_& m) {
  nb::class_<Config>(m, "Config",
                     "The one parameter set; fields by dotted name, e.g. 'map.voxel_size_m', with their types.")
      .def(nb::init<>())
      .def(nb::init<const Config&>(), "other"_a, "A copy of other.")
      .def(
          "set",
          [](Config& c, const std::string& name, nb::handle value) { set_config_field(c, name, text_of(value)); },
          "name"_a, "value"_a,
          "Sets a field from a number, bool or text; ValueError naming the field if it is unknown or out of range.")
      .def(
          "get", [](const Config& c, const std::string& name) { return to_python(get_config_value(c, name)); },
          "name"_a, "A field's value: float, int, bool, or the device name.")
      .def(
          "validate", [](const Config& c) { validate_config(c); },
          "Raises ValueError naming a field out of its range or a rule that fails.")
      .def_static(
          "fields",
          [] {
            Config c;
            nb::list out;
            for (const auto& f : config_fields(c)) {
              out.append(nb::make_tuple(f.name, to_python(get_config_value(c, f.name)), f.doc,
                                        f.valid.checked ? f.valid.describe() : std::string()));
            }
            return out;
          },
          "[(name, default, doc, valid range)] of every field, in the order of config.hpp.")
      .def(
          "to_dict",
          [](const Config& c) {
            nb::dict d;
            Config copy = c;
            for (const auto& f : config_fields(copy)) d[f.name.c_str()] = to_python(get_config_value(c, f.name));
            return d;
          },
          "{dotted name: typed value} of every field.")
      .def("__eq__",
           [](const Config& a, const Config& b) {
             Config copy = a;
             for (const auto& f : config_fields(copy)) {
               if (get_config_field(a, f.name) != get_config_field(b, f.name)) return false;
             }
             return true;
           })
      .def("__repr__", [](const Config& c) {
        // the fields that differ from the defaults
        const Config defaults;
        Config copy = c;
        std::string changed;
        for (const auto& f : config_fields(copy)) {
          const std::string value = get_config_field(c, f.name);
          if (value == get_config_field(defaults, f.name)) continue;
          changed += (changed.empty() ? "" : ", ") + f.name + "=" + value;
        }
        return "Config(" + (changed.empty() ? std::string("defaults") : changed) + ")";
      });

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

  nb::class_<pipeline::FrameTimings>(m, "FrameTimings")
      .def_ro("preprocess_s", &pipeline::FrameTimings::preprocess_s)
      .def_ro("covariance_s", &pipeline::FrameTimings::covariance_s)
      .def_ro("registration_s", &pipeline::FrameTimings::registration_s)
      .def_ro("map_update_s", &pipeline::FrameTimings::map_update_s)
      .def_ro("total_s", &pipeline::FrameTimings::total_s)
      .def_ro("device_timed", &pipeline::FrameTimings::device_timed, "stage times from CUDA events")
      .def("__repr__", attribute_repr({"preprocess_s", "covariance_s", "registration_s", "map_update_s", "total_s",
                                       "device_timed"}));

  nb::class_<pipeline::FrameResult>(m, "FrameResult", "What the scan pipeline made of one scan.")
      .def_ro("stamp_ns", &pipeline::FrameResult::stamp_ns)
      .def_ro("pose", &pipeline::FrameResult::pose)
      .def_ro("initial_guess", &pipeline::FrameResult::initial_guess)
      .def_ro("velocity_body_m_s", &pipeline::FrameResult::velocity_body_m_s)
      .def_ro("angular_velocity_body_rad_s", &pipeline::FrameResult::angular_velocity_body_rad_s)
      .def_ro("registered", &pipeline::FrameResult::registered)
      .def_ro("failure", &pipeline::FrameResult::failure,
              "why the registration's pose was not used (empty: it was); the scan kept the prediction")
      .def_ro("map_restarted", &pipeline::FrameResult::map_restarted,
              "the map restarted from this scan after registration failures (recovery)")
      .def_ro("non_finite_points", &pipeline::FrameResult::non_finite_points,
              "points dropped before the preprocessing for NaN or Inf coordinates or times")
      .def_ro("map_started_here", &pipeline::FrameResult::map_started_here,
              "the first registration found the body moving: this scan was undistorted again with that motion and "
              "the map started again from it")
      .def_ro("inlier_fraction", &pipeline::FrameResult::inlier_fraction,
              "inliers over source points of the registration (0 when not registered)")
      .def_ro("lost", &pipeline::FrameResult::lost,
              "localization in a prior map: the scan did not match the map (its pose is the prediction)")
      .def_ro("undistorted", &pipeline::FrameResult::undistorted, "whether the scan was undistorted")
      .def_prop_ro("converged", [](const pipeline::FrameResult& r) { return r.registration.converged; })
      .def_prop_ro("iterations", [](const pipeline::FrameResult& r) { return r.registration.iterations; })
      .def_prop_ro(
          "coarse_iterations", [](const pipeline::FrameResult& r) { return r.registration.coarse_iterations; },
          "of the iterations, those on every registration.coarse_stride-th source point")
      .def_prop_ro("inliers", [](const pipeline::FrameResult& r) { return r.registration.system.inliers; })
      .def_prop_ro("hessian", [](const pipeline::FrameResult& r) { return r.registration.system.H; })
      .def_prop_ro("gradient", [](const pipeline::FrameResult& r) { return r.registration.system.b; })
      .def_ro("sigma_m", &pipeline::FrameResult::sigma_m)
      .def_ro("kernel_scale_m", &pipeline::FrameResult::kernel_scale_m)
      .def_ro("density_limit", &pipeline::FrameResult::density_limit)
      .def_ro("input_points", &pipeline::FrameResult::input_points)
      .def_ro("kept_points", &pipeline::FrameResult::kept_points)
      .def_ro("source_points", &pipeline::FrameResult::source_points)
      .def_ro("map_voxels", &pipeline::FrameResult::map_voxels)
      .def_ro("map_points", &pipeline::FrameResult::map_points)
      .def_ro("timings", &pipeline::FrameResult::timings)
      .def("__repr__", attribute_repr({"stamp_ns", "pose", "registered", "converged", "iterations", "inliers",
                                       "sigma_m", "kernel_scale_m", "density_limit", "input_points", "kept_points",
                                       "source_points", "map_voxels", "map_points", "timings"}));

  nb::class_<registration::RegistrationResult>(m, "RegistrationResult", "Pose with the Gauss-Newton system.")
      .def_ro("pose", &registration::RegistrationResult::pose)
      .def_ro("iterations", &registration::RegistrationResult::iterations)
      .def_ro("coarse_iterations", &registration::RegistrationResult::coarse_iterations,
              "of the iterations, those on every registration.coarse_stride-th source point")
      .def_ro("converged", &registration::RegistrationResult::converged)
      .def_ro("budget_exceeded", &registration::RegistrationResult::budget_exceeded)
      .def_ro("held_directions", &registration::RegistrationResult::held_directions,
              "degenerate directions held at the initial guess in the last Gauss-Newton step")
      .def_ro("time_s", &registration::RegistrationResult::time_s)
      .def_prop_ro("hessian", [](const registration::RegistrationResult& r) { return r.system.H; })
      .def_prop_ro("gradient", [](const registration::RegistrationResult& r) { return r.system.b; })
      .def_prop_ro("error", [](const registration::RegistrationResult& r) { return r.system.error; })
      .def_prop_ro("inliers", [](const registration::RegistrationResult& r) { return r.system.inliers; })
      .def("__repr__",
           attribute_repr({"pose", "iterations", "converged", "budget_exceeded", "time_s", "error", "inliers"}));

  m.def(
      "register_pair",
      [](const Scan& source, const Scan& target, const SE3& guess, const Config& config) {
        return pipeline::register_pair(source.points, target.points, guess, config);
      },
      "source"_a, "target"_a, "initial_guess"_a = SE3(), "config"_a = Config(),
      nb::call_guard<nb::gil_scoped_release>(),
      "T_target_source by sparsity-aware GICP (the target becomes a voxel map).");

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

  nb::enum_<pipeline::LatencyModel>(m, "LatencyModel")
      .value("Measured", pipeline::LatencyModel::Measured)
      .value("Zero", pipeline::LatencyModel::Zero)
      .value("Fixed", pipeline::LatencyModel::Fixed);
  nb::class_<pipeline::ReplayOptions>(m, "ReplayOptions", "Latency model of the deterministic replay.")
      .def(nb::init<>())
      .def_rw("latency", &pipeline::ReplayOptions::latency)
      .def_rw("fixed_latency_s", &pipeline::ReplayOptions::fixed_latency_s)
      .def_rw("added_delay_s", &pipeline::ReplayOptions::added_delay_s);
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
      .def("__repr__", attribute_repr({"steps", "lidar_groups_accepted", "lidar_groups_rejected", "reinitializations",
                                       "imu_gaps", "imu_samples_dropped", "imu_samples_rejected", "accel_in_g",
                                       "gyro_bias_rad_s", "last_warning"}));
  nb::class_<PyOdometry>(m, "Odometry",
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
          "first scan.")
      .def_prop_ro("localizing",
                   [](PyOdometry& o) {
                     return locked(o, [](PyOdometry& x) { return x.odometry.scan_pipeline().localizing(); });
                   })
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

  m.def("export_resolution_m", &pipeline::export_resolution_m, "config"_a,
        "map.export_resolution_m, or the map's point spacing when 0 (after the first scan fixed the voxel size, "
        "pass the effective config)");
  nb::class_<PyMapExport>(m, "MapExport",
                          "The whole map of a run: every used scan, undistorted, at its pose, one centroid "
                          "(with the mean intensity) per cell of resolution_m; with a spill folder only the "
                          "tiles around the sensor stay in memory. Calls from several threads run one at a time.")
      .def(nb::init<double, const Config&, const std::string&>(), "resolution_m"_a, "config"_a, "spill_dir"_a = "",
           "spill_dir: a folder where tiles of map.export_tile_m the sensor has left wait until the end "
           "(memory bounded by the tiles around the sensor); '': all in memory")
      .def(
          "add",
          [](PyMapExport& e, const Scan& scan, const pipeline::FrameResult& r) {
            return locked(e, [&](PyMapExport& x) { return x.map.add(scan, r.motion, r.undistorted, r.pose); });
          },
          "scan"_a, "result"_a, nb::call_guard<nb::gil_scoped_release>(),
          "Adds a processed scan at its pose with the motion it was undistorted with; returns the points added.")
      .def(
          "add",
          [](PyMapExport& e, const Scan& scan, const pipeline::FrameResult& r, const SE3& pose) {
            return locked(e, [&](PyMapExport& x) { return x.map.add(scan, r.motion, r.undistorted, pose); });
          },
          "scan"_a, "result"_a, "pose"_a, nb::call_guard<nb::gil_scoped_release>(),
          "Adds a processed scan undistorted with the motion of its result, placed at `pose` (the LiDAR pose at "
          "the scan end in this map's frame: a keyframe's submap, a corrected trajectory); returns the points added.")
      .def(
          "points", [](PyMapExport& e) { return locked(e, [](PyMapExport& x) { return x.map.points(); }); },
          nb::call_guard<nb::gil_scoped_release>(),
          "The whole map as one Scan (in memory): one point per cell (centroid, mean intensity).")
      .def(
          "write",
          [](PyMapExport& e, const std::vector<std::filesystem::path>& paths) {
            locked(e, [&](PyMapExport& x) {
              std::vector<io::PointStreamWriter> writers;
              writers.reserve(paths.size());
              for (const auto& p : paths) writers.emplace_back(p, x.map.cells());
              x.map.for_each_piece([&](std::span<const Vec3f> points, std::span<const float> intensity) {
                for (auto& w : writers) w.append(points, intensity);
              });
              for (auto& w : writers) w.close();
            });
          },
          "paths"_a, nb::call_guard<nb::gil_scoped_release>(),
          "Streams the whole map, tile by tile, into each file (.pcd binary or .ply binary; x y z intensity).")
      .def_prop_ro("cells", [](PyMapExport& e) { return locked(e, [](PyMapExport& x) { return x.map.cells(); }); })
      .def_prop_ro("cells_in_memory",
                   [](PyMapExport& e) { return locked(e, [](PyMapExport& x) { return x.map.cells_in_memory(); }); })
      .def_prop_ro("tiles_on_disk",
                   [](PyMapExport& e) { return locked(e, [](PyMapExport& x) { return x.map.tiles_on_disk(); }); })
      .def_prop_ro("points_added",
                   [](PyMapExport& e) { return locked(e, [](PyMapExport& x) { return x.map.points_added(); }); })
      .def_prop_ro("resolution_m", [](PyMapExport& e) { return e.map.resolution_m(); })
      .def_prop_ro("memory_bytes",
                   [](PyMapExport& e) { return locked(e, [](PyMapExport& x) { return x.map.memory_bytes(); }); });

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
