// Bindings of the sequence generator (farlio._core.sim).
#include <nanobind/eigen/dense.h>
#include <nanobind/ndarray.h>
#include <nanobind/stl/map.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/vector.h>

#include "bindings.hpp"
#include "farlio/sim/sequence_generator.hpp"

namespace nb = nanobind;
using namespace nb::literals;

namespace farlio::python {
namespace {}  // namespace

void bind_sim(nb::module_& m) {
  using namespace farlio::sim;
  nb::enum_<Profile>(m, "Profile")
      .value("Racetrack", Profile::Racetrack)
      .value("Urban", Profile::Urban)
      .value("Handheld", Profile::Handheld)
      .value("Tunnel", Profile::Tunnel);
  m.def("parse_profile", &parse_profile, "name"_a, "'racetrack' | 'urban' | 'handheld' | 'tunnel'.");
  m.def("profile_name", &profile_name, "profile"_a);

  nb::class_<NoiseConfig>(m, "NoiseConfig", "LiDAR and IMU noise of a simulated sequence.")
      .def(nb::init<>())
      .def_rw("range_noise_std_m", &NoiseConfig::range_noise_std_m)
      .def_rw("dropout_probability", &NoiseConfig::dropout_probability)
      .def_rw("gyro_noise_std_rad_s", &NoiseConfig::gyro_noise_std_rad_s)
      .def_rw("accel_noise_std_m_s2", &NoiseConfig::accel_noise_std_m_s2)
      .def_rw("gyro_bias_walk_rad_s2_sqrt_hz", &NoiseConfig::gyro_bias_walk_rad_s2_sqrt_hz)
      .def_rw("accel_bias_walk_m_s3_sqrt_hz", &NoiseConfig::accel_bias_walk_m_s3_sqrt_hz)
      .def_rw("gyro_bias_initial_rad_s", &NoiseConfig::gyro_bias_initial_rad_s)
      .def_rw("accel_bias_initial_m_s2", &NoiseConfig::accel_bias_initial_m_s2);

  nb::class_<SimConfig>(m, "SimConfig", "Profile, seed, duration, noise and rates; see default_config().")
      .def(nb::init<>())
      .def_rw("profile", &SimConfig::profile)
      .def_rw("seed", &SimConfig::seed)
      .def_rw("duration_s", &SimConfig::duration_s)
      .def_rw("noise", &SimConfig::noise)
      .def_rw("noise_free", &SimConfig::noise_free)
      .def_rw("start_stamp_ns", &SimConfig::start_stamp_ns)
      .def_rw("lidar_rate_hz", &SimConfig::lidar_rate_hz)
      .def_rw("imu_rate_hz", &SimConfig::imu_rate_hz)
      .def_rw("gravity_m_s2", &SimConfig::gravity_m_s2);
  m.def("default_config", &default_config, "profile"_a, "The documented defaults of a profile.");
  m.def(
      "default_config", [](const std::string& name) { return default_config(parse_profile(name)); }, "profile"_a);

  nb::class_<BodyState>(m, "BodyState", "Exact state of the body (IMU) frame.")
      .def_ro("pose_world_body", &BodyState::pose_world_body)
      .def_ro("velocity_world_m_s", &BodyState::velocity_world_m_s)
      .def_ro("acceleration_world_m_s2", &BodyState::acceleration_world_m_s2)
      .def_ro("angular_velocity_body_rad_s", &BodyState::angular_velocity_body_rad_s);

  nb::class_<SequenceGenerator>(m, "SequenceGenerator", "LiDAR + IMU sequence with exact ground truth.")
      .def(nb::init<const SimConfig&>(), "config"_a)
      .def("num_scans", &SequenceGenerator::num_scans)
      .def("scan", &SequenceGenerator::scan, "i"_a, nb::call_guard<nb::gil_scoped_release>(),
           "Scan i (deterministic from seed and i; releases the GIL).")
      .def("motion_compensated", &SequenceGenerator::motion_compensated, "scan"_a,
           nb::call_guard<nb::gil_scoped_release>(),
           "The scan as KITTI stores its scans: in the LiDAR frame at the scan end, no per-point times.")
      .def("imu", &SequenceGenerator::imu, nb::call_guard<nb::gil_scoped_release>(),
           "All IMU samples over the duration as a list of ImuSample.")
      .def(
          "imu_arrays",
          [](const SequenceGenerator& g) {
            std::vector<ImuSample> samples;
            {
              nb::gil_scoped_release release;
              samples = g.imu();
            }
            std::vector<std::int64_t> stamps(samples.size());
            std::vector<double> gyro(3 * samples.size()), accel(3 * samples.size());
            for (std::size_t k = 0; k < samples.size(); ++k) {
              stamps[k] = samples[k].stamp_ns;
              for (int a = 0; a < 3; ++a) {
                gyro[3 * k + static_cast<std::size_t>(a)] = samples[k].gyro_rad_s[a];
                accel[3 * k + static_cast<std::size_t>(a)] = samples[k].accel_m_s2[a];
              }
            }
            const std::size_t n = samples.size();
            return nb::make_tuple(owned_array(std::move(stamps), {n}), owned_array(std::move(gyro), {n, 3}),
                                  owned_array(std::move(accel), {n, 3}));
          },
          "(stamp_ns [N] int64, gyro_rad_s [N, 3], accel_m_s2 [N, 3]) numpy arrays.")
      .def("state", &SequenceGenerator::state, "stamp_ns"_a)
      .def("groundtruth_body", &SequenceGenerator::groundtruth_body, "rate_hz"_a)
      .def("groundtruth_scans", &SequenceGenerator::groundtruth_scans)
      .def("T_imu_lidar", &SequenceGenerator::T_imu_lidar)
      .def("lidar_rate_hz", &SequenceGenerator::lidar_rate_hz)
      .def("imu_rate_hz", &SequenceGenerator::imu_rate_hz)
      .def("gravity_m_s2", &SequenceGenerator::gravity_m_s2)
      .def("scan_period_ns", &SequenceGenerator::scan_period_ns)
      .def("description", &SequenceGenerator::description)
      .def_prop_ro("config", &SequenceGenerator::config);
}

}  // namespace farlio::python
