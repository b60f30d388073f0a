#include "bindings.hpp"
#include "farlio/core/error.hpp"

namespace nb = nanobind;

NB_MODULE(_core, m) {
  m.doc() = "farlio C++ core (nanobind bindings)";
  nb::exception<farlio::InputError>(m, "InputError", PyExc_ValueError);
  nb::exception<farlio::CapacityError>(m, "CapacityError", PyExc_RuntimeError);
  farlio::python::bind_core(m);
  auto io = m.def_submodule("io", "file formats and the sequence folder");
  farlio::python::bind_io(io);
  farlio::python::bind_pointcloud2(io);
  auto sim = m.def_submodule("sim", "LiDAR + IMU sequence generator");
  farlio::python::bind_sim(sim);
  auto ev = m.def_submodule("eval", "trajectory evaluation: APE, RPE, coverage");
  farlio::python::bind_eval(ev);
  farlio::python::bind_config(m);
  farlio::python::bind_stage_limits(m);
  farlio::python::bind_scan_results(m);
  farlio::python::bind_registration(m);
  farlio::python::bind_clock_check(m);
  farlio::python::bind_odometry(m);
  farlio::python::bind_map_export(m);
  farlio::python::bind_online_odometry(m);
  farlio::python::bind_scan_pipeline(m);
}
