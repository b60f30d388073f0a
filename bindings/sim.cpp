// Bindings of the sequence generator (farlio._core.sim).
#include <nanobind/eigen/dense.h>
#include <nanobind/ndarray.h>
#include <nanobind/stl/map.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/vector.h>

#include "bindings.hpp"
#include "farlio/sim/imu_errors.hpp"
#include "farlio/sim/imu_grade.hpp"
#include "farlio/sim/sequence_generator.hpp"

namespace nb = nanobind;
using namespace nb::literals;

namespace farlio::python {
namespace {

/// The profiles and LiDAR models, with their names.
void bind_profiles(nb::module_& m) {
  using namespace farlio::sim;
  nb::enum_<Profile>(m, "Profile")
      .value("Racetrack", Profile::Racetrack)
      .value("Urban", Profile::Urban)
      .value("Handheld", Profile::Handheld)
      .value("Tunnel", Profile::Tunnel)
      .value("Garage", Profile::Garage);
  m.def("parse_profile", &parse_profile, "name"_a, "'racetrack' | 'urban' | 'handheld' | 'tunnel' | 'garage'.");
  m.def("profile_name", &profile_name, "profile"_a);
  nb::enum_<LidarModel>(m, "LidarModel")
      .value("Profile", LidarModel::Profile)
      .value("Avia", LidarModel::Avia)
      .value("Mid360", LidarModel::Mid360)
      .value("Vlp16", LidarModel::Vlp16)
      .value("Hdl32", LidarModel::Hdl32)
      .value("Os128", LidarModel::Os128);
  m.def("parse_lidar_model", &parse_lidar_model, "name"_a,
        "'profile' | 'avia' | 'mid360' | 'vlp16' | 'hdl32' | 'os128' (docs/simulation.md, 'LiDAR models').");
  m.def("lidar_model_name", &lidar_model_name, "model"_a);
}

/// The sensors' noise and the IMU error model: configs, a run's draw, the datasheet grades.
void bind_imu_errors(nb::module_& m) {
  using namespace farlio::sim;
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

  nb::class_<VibrationConfig>(m, "VibrationConfig",
                              "Mount vibration growing with speed: wheel-order sinusoid + broadband noise.")
      .def(nb::init<>())
      .def_rw("wheel_radius_m", &VibrationConfig::wheel_radius_m)
      .def_rw("accel_wheel_amplitude_m_s2_per_m_s", &VibrationConfig::accel_wheel_amplitude_m_s2_per_m_s)
      .def_rw("gyro_wheel_amplitude_rad_s_per_m_s", &VibrationConfig::gyro_wheel_amplitude_rad_s_per_m_s)
      .def_rw("accel_noise_std_m_s2_per_m_s", &VibrationConfig::accel_noise_std_m_s2_per_m_s)
      .def_rw("gyro_noise_std_rad_s_per_m_s", &VibrationConfig::gyro_noise_std_rad_s_per_m_s)
      .def("any", &VibrationConfig::any);

  nb::class_<ImuErrorConfig>(m, "ImuErrorConfig",
                             "Turn-on bias, scale factor, misalignment, g-sensitivity and vibration of the IMU.")
      .def(nb::init<>())
      .def_rw("gyro_turn_on_bias_std_rad_s", &ImuErrorConfig::gyro_turn_on_bias_std_rad_s)
      .def_rw("accel_turn_on_bias_std_m_s2", &ImuErrorConfig::accel_turn_on_bias_std_m_s2)
      .def_rw("gyro_scale_factor_std_ppm", &ImuErrorConfig::gyro_scale_factor_std_ppm)
      .def_rw("accel_scale_factor_std_ppm", &ImuErrorConfig::accel_scale_factor_std_ppm)
      .def_rw("gyro_misalignment_std_mrad", &ImuErrorConfig::gyro_misalignment_std_mrad)
      .def_rw("accel_misalignment_std_mrad", &ImuErrorConfig::accel_misalignment_std_mrad)
      .def_rw("gyro_g_sensitivity_std_rad_s_per_m_s2", &ImuErrorConfig::gyro_g_sensitivity_std_rad_s_per_m_s2)
      .def_rw("vibration", &ImuErrorConfig::vibration)
      .def("any", &ImuErrorConfig::any);

  nb::class_<ImuErrorDraw>(m, "ImuErrorDraw", "The IMU error constants of one run, drawn from the seed.")
      .def_ro("gyro_turn_on_bias_rad_s", &ImuErrorDraw::gyro_turn_on_bias_rad_s)
      .def_ro("accel_turn_on_bias_m_s2", &ImuErrorDraw::accel_turn_on_bias_m_s2)
      .def_ro("gyro_response", &ImuErrorDraw::gyro_response)
      .def_ro("accel_response", &ImuErrorDraw::accel_response)
      .def_ro("gyro_g_sensitivity_rad_s_per_m_s2", &ImuErrorDraw::gyro_g_sensitivity_rad_s_per_m_s2);
  m.def("draw_imu_errors", &draw_imu_errors, "config"_a, "seed"_a, "The error constants of a run (ImuErrorDraw).");

  nb::enum_<ImuGrade>(m, "ImuGrade")
      .value("Profile", ImuGrade::Profile)
      .value("Ideal", ImuGrade::Ideal)
      .value("Consumer", ImuGrade::Consumer)
      .value("Industrial", ImuGrade::Industrial)
      .value("Tactical", ImuGrade::Tactical);
  m.def("parse_imu_grade", &parse_imu_grade, "name"_a, "'profile' | 'ideal' | 'consumer' | 'industrial' | 'tactical'.");
  m.def("imu_grade_name", &imu_grade_name, "grade"_a);
}

/// SimConfig and its defaults per profile.
void bind_sim_config(nb::module_& m) {
  using namespace farlio::sim;
  nb::class_<SimConfig>(m, "SimConfig", "Profile, seed, duration, noise and rates; see default_config().")
      .def(nb::init<>())
      .def_rw("profile", &SimConfig::profile)
      .def_rw("seed", &SimConfig::seed)
      .def_rw("duration_s", &SimConfig::duration_s)
      .def_rw("noise", &SimConfig::noise)
      .def_rw("imu_errors", &SimConfig::imu_errors)
      .def_rw("noise_free", &SimConfig::noise_free)
      .def_rw("start_stamp_ns", &SimConfig::start_stamp_ns)
      .def_rw("motion_start_s", &SimConfig::motion_start_s,
              "t = 0 of the sequence is this instant of the profile's motion (s; 0: at its start, at rest)")
      .def_rw("lidar_model", &SimConfig::lidar_model,
              "the LiDAR on the vehicle: the profile's own sensors (Profile) or one sensor of a named model")
      .def_rw("lidar_rate_hz", &SimConfig::lidar_rate_hz)
      .def_rw("imu_rate_hz", &SimConfig::imu_rate_hz)
      .def_rw("imu_time_offset_s", &SimConfig::imu_time_offset_s,
              "the IMU's samples fall this long after the whole IMU periods of the sequence clock (s, below "
              "1 / imu_rate_hz)")
      .def_rw("gravity_m_s2", &SimConfig::gravity_m_s2);
  m.def("default_config", &default_config, "profile"_a, "The documented defaults of a profile.");
  m.def(
      "default_config", [](const std::string& name) { return default_config(parse_profile(name)); }, "profile"_a);
  m.def(
      "apply_imu_grade",
      [](SimConfig config, const std::string& grade, bool vibration) {
        apply_imu_grade(config, parse_imu_grade(grade), vibration);
        return config;
      },
      "config"_a, "grade"_a, "vibration"_a = true,
      "A copy of config with the IMU set to a grade (profile: unchanged; ideal: no IMU error; consumer, industrial, "
      "tactical: datasheet classes plus the profile's vibration unless vibration=False).");
}

/// BodyState and SequenceGenerator.
void bind_sequence_generator(nb::module_& m) {
  using namespace farlio::sim;
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
      .def(
          "surface_distance_m",
          [](const SequenceGenerator& g, const Eigen::Matrix<double, Eigen::Dynamic, 3>& points) {
            Eigen::VectorXd out(points.rows());
            for (Eigen::Index i = 0; i < points.rows(); ++i) {
              out(i) = g.scene().surface_distance_m(points.row(i).transpose());
            }
            return out;
          },
          "points"_a, nb::call_guard<nb::gil_scoped_release>(),
          "Distance of each world point ((N, 3)) to the nearest surface of the scene (brute force: for tests).")
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

}  // namespace

void bind_sim(nb::module_& m) {
  bind_profiles(m);
  bind_imu_errors(m);
  bind_sim_config(m);
  bind_sequence_generator(m);
}

}  // namespace farlio::python
