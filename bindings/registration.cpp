// Bindings of a registration's result and of the registration of one scan against another.
#include <nanobind/eigen/dense.h>
#include <nanobind/stl/filesystem.h>
#include <nanobind/stl/optional.h>
#include <nanobind/stl/pair.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/tuple.h>
#include <nanobind/stl/vector.h>

#include "bindings.hpp"
#include "farlio/pipeline/pairwise.hpp"
#include "farlio/registration/gicp.hpp"
#include "repr.hpp"

namespace nb = nanobind;
using namespace nb::literals;

namespace farlio::python {

/// RegistrationResult and register_pair.
void bind_registration(nb::module_& m) {
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
}

}  // namespace farlio::python
