#pragma once
// Each part of the library binds itself into its own submodule of farlio._core.
#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>

#include <initializer_list>
#include <vector>

#include "farlio/core/types.hpp"

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

void bind_core(nanobind::module_& m);         // core.cpp: Scan, ImuSample, SE3, Trajectory, Device
void bind_io(nanobind::module_& m);           // io.cpp: file formats, sequence folder
void bind_pointcloud2(nanobind::module_& m);  // pointcloud2.cpp: sensor_msgs/PointCloud2 decoding (into io)
void bind_sim(nanobind::module_& m);          // sim.cpp: sequence generator
void bind_eval(nanobind::module_& m);         // eval.cpp: APE, RPE, coverage
void bind_pipeline(nanobind::module_& m);     // pipeline.cpp: Config, ScanPipeline, results
}  // namespace farlio::python
