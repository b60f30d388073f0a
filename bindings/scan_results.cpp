// Bindings of what the scan pipeline reports for one scan: its result and its stage times.
#include <nanobind/eigen/dense.h>
#include <nanobind/stl/filesystem.h>
#include <nanobind/stl/optional.h>
#include <nanobind/stl/pair.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/tuple.h>
#include <nanobind/stl/vector.h>

#include "bindings.hpp"
#include "farlio/pipeline/frame_timings.hpp"
#include "farlio/pipeline/scan_pipeline.hpp"
#include "repr.hpp"

namespace nb = nanobind;
using namespace nb::literals;

namespace farlio::python {

/// FrameTimings and FrameResult.
void bind_scan_results(nb::module_& m) {
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
}

}  // namespace farlio::python
