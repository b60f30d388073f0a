#pragma once
// Each part of the library binds itself into its own submodule of farlio._core.
#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>

#include <Eigen/Core>
#include <initializer_list>
#include <vector>

#include "farlio/core/types.hpp"
#include "farlio/map/map_snapshot.hpp"

namespace farlio::python {

/// A numpy array that owns `values` (moved to the heap, freed with the array), of the given shape.
template <typename T>
nanobind::ndarray<nanobind::numpy, T> owned_array(std::vector<T> values, std::initializer_list<std::size_t> shape) {
  auto* heap = new std::vector<T>(std::move(values));
  nanobind::capsule owner(heap, [](void* p) noexcept { delete static_cast<std::vector<T>*>(p); });
  return nanobind::ndarray<nanobind::numpy, T>(heap->data(), shape, owner);
}

/// A numpy view of `values` (no copy) that keeps `owner`, the Python object holding them, alive.
template <typename T>
nanobind::ndarray<nanobind::numpy, T, nanobind::ndim<1>> vector_view(std::vector<T>& values, nanobind::handle owner) {
  return nanobind::ndarray<nanobind::numpy, T, nanobind::ndim<1>>(values.data(), {values.size()}, owner);
}

/// An (N, 3) float32 numpy view of `points` (no copy) that keeps `owner` alive.
inline nanobind::ndarray<nanobind::numpy, float, nanobind::shape<-1, 3>> points_view(std::vector<Vec3f>& points,
                                                                                     nanobind::handle owner) {
  return {points.empty() ? nullptr : points.data()->data(), {points.size(), 3}, owner};
}

/// (N, 3) float32 rows, as numpy wants them.
using PointRows = Eigen::Matrix<float, Eigen::Dynamic, 3, Eigen::RowMajor>;

inline PointRows point_rows(const std::vector<Eigen::Vector3f>& pts) {
  PointRows out(static_cast<Eigen::Index>(pts.size()), 3);
  for (std::size_t i = 0; i < pts.size(); ++i) out.row(static_cast<Eigen::Index>(i)) = pts[i].transpose();
  return out;
}

/// The points of a map snapshot as rows.
inline PointRows map_points(const map::MapSnapshot& snapshot) {
  std::vector<Eigen::Vector3f> pts;
  snapshot.for_each_point([&](const Eigen::Vector3f& x, const map::Cov3&, bool) { pts.push_back(x); });
  return point_rows(pts);
}

void bind_core(nanobind::module_& m);         // core.cpp: Scan, ImuSample, SE3, Trajectory, Device
void bind_io(nanobind::module_& m);           // io.cpp: file formats, sequence folder
void bind_pointcloud2(nanobind::module_& m);  // pointcloud2.cpp: sensor_msgs/PointCloud2 decoding (into io)
void bind_sim(nanobind::module_& m);          // sim.cpp: sequence generator
void bind_eval(nanobind::module_& m);         // eval.cpp: APE, RPE, coverage
// The top-level module's classes, bound in this order (a default argument's type comes first):
void bind_config(nanobind::module_& m);           // config.cpp: Config
void bind_stage_limits(nanobind::module_& m);     // stage_limits.cpp: Yardsticks, stage_limits
void bind_scan_results(nanobind::module_& m);     // scan_results.cpp: FrameTimings, FrameResult
void bind_registration(nanobind::module_& m);     // registration.cpp: RegistrationResult, register_pair
void bind_clock_check(nanobind::module_& m);      // clock_check.cpp: ClockCheck, check_clocks
void bind_odometry(nanobind::module_& m);         // odometry.cpp: Odometry, its options and reports
void bind_map_export(nanobind::module_& m);       // map_export.cpp: MapExport
void bind_online_odometry(nanobind::module_& m);  // online_odometry.cpp: OnlineOdometry, OdometrySample
void bind_scan_pipeline(nanobind::module_& m);    // scan_pipeline.cpp: ScanPipeline
}  // namespace farlio::python
