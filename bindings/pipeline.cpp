// Bindings of the parameter set and the scan pipeline.
#include <nanobind/eigen/dense.h>
#include <nanobind/stl/optional.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/tuple.h>
#include <nanobind/stl/vector.h>

#include "bindings.hpp"
#include "farlio/core/config_fields.hpp"
#include "farlio/pipeline/scan_pipeline.hpp"

namespace nb = nanobind;
using namespace nb::literals;

namespace farlio::python {

void bind_pipeline(nb::module_& m) {
  nb::class_<Config>(m, "Config", "The one parameter set; fields by dotted name, e.g. 'map.voxel_size_m'.")
      .def(nb::init<>())
      .def("set", &set_config_field, "name"_a, "value"_a, "Sets a field from text (raises ValueError if unknown).")
      .def("get", &get_config_field, "name"_a, "A field's value as text.")
      .def_static(
          "fields",
          [] {
            Config c;
            std::vector<std::tuple<std::string, std::string, std::string>> out;
            for (const auto& f : config_fields(c)) out.emplace_back(f.name, get_config_field(c, f.name), f.doc);
            return out;
          },
          "[(name, default, doc)] of every field.")
      .def("to_dict", [](const Config& c) {
        nb::dict d;
        Config copy = c;
        for (const auto& f : config_fields(copy)) d[f.name.c_str()] = get_config_field(c, f.name);
        return d;
      });

  nb::class_<pipeline::FrameTimings>(m, "FrameTimings")
      .def_ro("preprocess_s", &pipeline::FrameTimings::preprocess_s)
      .def_ro("covariance_s", &pipeline::FrameTimings::covariance_s)
      .def_ro("registration_s", &pipeline::FrameTimings::registration_s)
      .def_ro("map_update_s", &pipeline::FrameTimings::map_update_s)
      .def_ro("total_s", &pipeline::FrameTimings::total_s);

  nb::class_<pipeline::FrameResult>(m, "FrameResult", "What the scan pipeline made of one scan.")
      .def_ro("stamp_ns", &pipeline::FrameResult::stamp_ns)
      .def_ro("pose", &pipeline::FrameResult::pose)
      .def_ro("initial_guess", &pipeline::FrameResult::initial_guess)
      .def_ro("velocity_body_m_s", &pipeline::FrameResult::velocity_body_m_s)
      .def_ro("angular_velocity_body_rad_s", &pipeline::FrameResult::angular_velocity_body_rad_s)
      .def_ro("registered", &pipeline::FrameResult::registered)
      .def_prop_ro("converged", [](const pipeline::FrameResult& r) { return r.registration.converged; })
      .def_prop_ro("iterations", [](const pipeline::FrameResult& r) { return r.registration.iterations; })
      .def_prop_ro("inliers", [](const pipeline::FrameResult& r) { return r.registration.system.inliers; })
      .def_prop_ro("hessian", [](const pipeline::FrameResult& r) { return r.registration.system.H; })
      .def_prop_ro("gradient", [](const pipeline::FrameResult& r) { return r.registration.system.b; })
      .def_ro("sigma_m", &pipeline::FrameResult::sigma_m)
      .def_ro("density_limit", &pipeline::FrameResult::density_limit)
      .def_ro("input_points", &pipeline::FrameResult::input_points)
      .def_ro("kept_points", &pipeline::FrameResult::kept_points)
      .def_ro("source_points", &pipeline::FrameResult::source_points)
      .def_ro("map_voxels", &pipeline::FrameResult::map_voxels)
      .def_ro("map_points", &pipeline::FrameResult::map_points)
      .def_ro("timings", &pipeline::FrameResult::timings);

  nb::class_<pipeline::ScanPipeline>(m, "ScanPipeline",
                                     "preprocess -> sparsity-aware GICP against the adaptive submap -> map update")
      .def(nb::init<const Config&, const SE3&>(), "config"_a = Config(), "initial_pose"_a = SE3())
      .def(
          "process",
          [](pipeline::ScanPipeline& p, const Scan& scan, const std::optional<SE3>& guess) {
            return p.process(scan, guess);
          },
          "scan"_a, "initial_guess"_a = nb::none(), nb::call_guard<nb::gil_scoped_release>(),
          "Registers one scan; without a guess the constant-velocity model supplies one.")
      .def_prop_ro("frames", &pipeline::ScanPipeline::frames)
      .def(
          "map_points",
          [](const pipeline::ScanPipeline& p) {
            std::vector<Eigen::Vector3f> pts;
            p.local_map().for_each_point([&](const Eigen::Vector3f& x, const map::Cov3&, bool) { pts.push_back(x); });
            Eigen::MatrixX3f out(static_cast<Eigen::Index>(pts.size()), 3);
            for (std::size_t i = 0; i < pts.size(); ++i) out.row(static_cast<Eigen::Index>(i)) = pts[i].transpose();
            return out;
          },
          "(N, 3) float32 copy of the submap's points (world frame)")
      .def_prop_ro("map_memory_bytes", [](const pipeline::ScanPipeline& p) { return p.local_map().memory_bytes(); });
}

}  // namespace farlio::python
