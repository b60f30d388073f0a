#pragma once
// Each part of the library binds itself into its own submodule of farlio._core.
#include <nanobind/nanobind.h>

namespace farlio::python {
void bind_core(nanobind::module_& m);  // core.cpp: Scan, ImuSample, SE3, Trajectory, Device
void bind_io(nanobind::module_& m);    // io.cpp: file formats, sequence folder
void bind_sim(nanobind::module_& m);   // sim.cpp: sequence generator
void bind_eval(nanobind::module_& m);  // eval.cpp: APE, RPE, coverage
void bind_pipeline(nanobind::module_& m);  // pipeline.cpp: Config, ScanPipeline, results
}  // namespace farlio::python
