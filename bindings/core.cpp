// Bindings of the data model. Per-point arrays of a Scan are numpy views into the C++ vectors
// (no copy); the view keeps its Scan alive.
#include <nanobind/eigen/dense.h>
#include <nanobind/ndarray.h>
#include <nanobind/stl/optional.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/vector.h>

#include "bindings.hpp"
#include "farlio/core/se3.hpp"
#include "farlio/core/time.hpp"
#include "farlio/core/trajectory.hpp"
#include "farlio/core/types.hpp"
#include "farlio/fusion/euler.hpp"
#include "farlio/pipeline/backend_availability.hpp"
#include "repr.hpp"

namespace nb = nanobind;
using namespace nb::literals;

namespace farlio::python {
namespace {

template <typename T>
using In1 = nb::ndarray<const T, nb::ndim<1>, nb::c_contig, nb::device::cpu>;
using InPoints = nb::ndarray<const float, nb::shape<-1, 3>, nb::c_contig, nb::device::cpu>;

template <typename T>
void assign(std::vector<T>& dst, const std::optional<In1<T>>& src, std::size_t n, const char* name) {
  if (!src) {
    dst.clear();
    return;
  }
  if (src->shape(0) != n) {
    throw nb::value_error((std::string(name) + " must have one value per point").c_str());
  }
  dst.assign(src->data(), src->data() + n);
}

void set_points(Scan& s, const InPoints& p) {
  s.points.resize(p.shape(0));
  std::copy_n(p.data(), 3 * p.shape(0), s.points.data()->data());
}

std::string scan_repr(const Scan& s) {
  std::vector<std::string> fields;  // the per-point arrays the scan has besides its points
  if (!s.time_s.empty()) fields.emplace_back("time_s");
  if (!s.intensity.empty()) fields.emplace_back("intensity");
  if (!s.sensor_id.empty()) fields.emplace_back("sensor_id");
  return Repr("Scan")
      .item(std::to_string(s.size()) + " points")
      .field("duration_s", s.duration_s())
      .field("start_stamp_ns", s.start_stamp_ns)
      .field("end_stamp_ns", s.end_stamp_ns)
      .field("fields", fields)
      .str();
}

std::string trajectory_repr(const Trajectory& t) {
  Repr r("Trajectory");
  r.item(std::to_string(t.size()) + " poses");
  if (t.size() == 0) return r.str();
  return r.field("first_stamp_ns", t[0].stamp_ns)
      .field("last_stamp_ns", t[t.size() - 1].stamp_ns)
      .field("path_length_m", t.path_length_m())
      .field("first", t[0].pose)
      .field("last", t[t.size() - 1].pose)
      .str();
}

/// Scan: points and per-point arrays as numpy views.
void bind_scan(nb::module_& m) {
  nb::class_<Scan>(m, "Scan", "One LiDAR scan: float32 points with per-point times (s since scan start).")
      .def(
          "__init__",
          [](Scan* s, const InPoints& points, std::optional<In1<float>> time_s, std::optional<In1<float>> intensity,
             std::int64_t start_stamp_ns, std::int64_t end_stamp_ns, std::optional<In1<std::uint8_t>> sensor_id) {
            new (s) Scan();
            set_points(*s, points);
            assign(s->time_s, time_s, s->size(), "time_s");
            assign(s->intensity, intensity, s->size(), "intensity");
            assign(s->sensor_id, sensor_id, s->size(), "sensor_id");
            s->start_stamp_ns = start_stamp_ns;
            s->end_stamp_ns = end_stamp_ns;
            s->validate("Scan");
          },
          "points"_a, "time_s"_a = nb::none(), "intensity"_a = nb::none(), "start_stamp_ns"_a = 0, "end_stamp_ns"_a = 0,
          "sensor_id"_a = nb::none())
      .def_rw("start_stamp_ns", &Scan::start_stamp_ns)
      .def_rw("end_stamp_ns", &Scan::end_stamp_ns)
      .def_prop_ro(
          "points", [](nb::handle self) { return points_view(nb::cast<Scan&>(self).points, self); },
          "(N, 3) float32 view of the points (LiDAR frame, raw)")
      .def_prop_ro(
          "time_s", [](nb::handle self) { return vector_view(nb::cast<Scan&>(self).time_s, self); },
          "(N,) float32 view: per-point time in s since scan start (empty: none)")
      .def_prop_ro(
          "intensity", [](nb::handle self) { return vector_view(nb::cast<Scan&>(self).intensity, self); },
          "(N,) float32 view of intensities (empty: none)")
      .def_prop_ro(
          "sensor_id", [](nb::handle self) { return vector_view(nb::cast<Scan&>(self).sensor_id, self); },
          "(N,) uint8 view of sensor indices (empty: none)")
      .def("__len__", &Scan::size)
      .def_prop_ro("duration_s", &Scan::duration_s)
      .def("remove_non_finite", &Scan::remove_non_finite, "Drops NaN/Inf points; returns how many.")
      .def("__repr__", &scan_repr);
}

/// ImuSample.
void bind_imu_sample(nb::module_& m) {
  nb::class_<ImuSample>(m, "ImuSample", "One IMU reading in the body frame.")
      .def(nb::init<>())
      .def(
          "__init__",
          [](ImuSample* s, std::int64_t stamp_ns, const Vec3d& gyro, const Vec3d& accel) {
            new (s) ImuSample{stamp_ns, gyro, accel};
          },
          "stamp_ns"_a, "gyro_rad_s"_a, "accel_m_s2"_a)
      .def_rw("stamp_ns", &ImuSample::stamp_ns)
      .def_rw("gyro_rad_s", &ImuSample::gyro_rad_s)
      .def_rw("accel_m_s2", &ImuSample::accel_m_s2)
      .def("__repr__", attribute_repr({"stamp_ns", "gyro_rad_s", "accel_m_s2"}));
}

/// SE3 and rotation_from_euler.
void bind_se3(nb::module_& m) {
  m.def("rotation_from_euler", &fusion::rotation_from_euler, "rpy_rad"_a,
        "Rotation matrix (body -> world) of [roll, pitch, yaw] in radians: Rz(yaw) Ry(pitch) Rx(roll).");
  nb::class_<SE3>(m, "SE3", "Rigid transform; tangent vectors are [translation; rotation].")
      .def(nb::init<>())
      .def_static("from_matrix", &SE3::from_matrix, "m"_a)
      .def_static("exp", &SE3::exp, "xi"_a)
      .def("log", &SE3::log)
      .def("matrix", &SE3::matrix)
      .def("inverse", &SE3::inverse)
      .def("rotation", &SE3::rotation)
      .def_prop_ro("translation", [](const SE3& t) { return Vec3d(t.translation()); })
      .def_prop_ro("quaternion_xyzw",
                   [](const SE3& t) {
                     const auto& q = t.quaternion();
                     return Eigen::Vector4d(q.x(), q.y(), q.z(), q.w());
                   })
      .def("angle_rad", &SE3::angle_rad)
      .def("__mul__", [](const SE3& a, const SE3& b) { return a * b; })
      .def("__mul__", [](const SE3& a, const Vec3d& p) { return Vec3d(a * p); })
      .def("__repr__", [](const SE3& t) { return repr_value(t); });
}

/// Trajectory.
void bind_trajectory(nb::module_& m) {
  nb::class_<Trajectory>(m, "Trajectory", "Time-ordered poses of one frame in the world.")
      .def(nb::init<>())
      .def("push_back", &Trajectory::push_back, "stamp_ns"_a, "pose"_a)
      .def("__len__", &Trajectory::size)
      .def("__getitem__",
           [](const Trajectory& t, std::size_t i) {
             if (i >= t.size()) throw nb::index_error();
             return nb::make_tuple(t[i].stamp_ns, t[i].pose);
           })
      .def_prop_ro(
          "stamps_ns",
          [](const Trajectory& t) {
            std::vector<std::int64_t> v;
            for (const auto& p : t) v.push_back(p.stamp_ns);
            return owned_array(std::move(v), {t.size()});
          },
          nb::rv_policy::move, "(N,) int64 stamps in ns (a copy)")
      .def(
          "matrices",
          [](const Trajectory& t) {
            std::vector<double> v;
            v.reserve(16 * t.size());
            for (const auto& p : t) {
              const Eigen::Matrix<double, 4, 4, Eigen::RowMajor> mm = p.pose.matrix();
              v.insert(v.end(), mm.data(), mm.data() + 16);
            }
            return owned_array(std::move(v), {t.size(), 4, 4});
          },
          "(N, 4, 4) pose matrices (a copy)")
      .def("interpolate_at", &Trajectory::interpolate_at, "stamp_ns"_a)
      .def("transformed", &Trajectory::transformed, "extrinsic"_a)
      .def("between", &Trajectory::between, "begin_ns"_a, "end_ns"_a,
           "The poses stamped within [begin_ns, end_ns] (a stretch of the run).")
      .def("path_length_m", &Trajectory::path_length_m)
      .def("is_time_ordered", &Trajectory::is_time_ordered)
      .def("__repr__", &trajectory_repr);
}

}  // namespace

void bind_core(nb::module_& m) {
  bind_scan(m);
  bind_imu_sample(m);
  bind_se3(m);
  bind_trajectory(m);
  m.attr("NS_PER_S") = kNsPerSecond;  // stamps are integer ns
  m.def("cuda_compiled", &cuda_compiled, "True if this build contains the CUDA backend.");
  m.def("cuda_device_count", &cuda_device_count, "Number of usable CUDA devices.");
}

}  // namespace farlio::python
