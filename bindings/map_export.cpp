// Bindings of the whole map of a run (export).
#include "farlio/pipeline/map_export.hpp"

#include <nanobind/eigen/dense.h>
#include <nanobind/stl/filesystem.h>
#include <nanobind/stl/optional.h>
#include <nanobind/stl/pair.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/tuple.h>
#include <nanobind/stl/vector.h>

#include <filesystem>
#include <mutex>
#include <span>
#include <string>
#include <vector>

#include "bindings.hpp"
#include "farlio/io/point_stream_writer.hpp"
#include "farlio/pipeline/scan_pipeline.hpp"
#include "locked.hpp"

namespace nb = nanobind;
using namespace nb::literals;

namespace farlio::python {
namespace {

/// A map export and the mutex its calls take.
struct PyMapExport {
  std::mutex mutex;
  pipeline::MapExport map;
  PyMapExport(double resolution_m, const Config& config, const std::string& spill_dir)
      : map(resolution_m, config.preprocess, config.num_threads, spill_dir, config.map.export_tile_m) {}
};

}  // namespace

/// export_resolution_m and MapExport.
void bind_map_export(nb::module_& m) {
  m.def("export_resolution_m", &pipeline::export_resolution_m, "config"_a,
        "map.export_resolution_m, or the map's point spacing when 0 (after the first scan fixed the voxel size, "
        "pass the effective config)");
  nb::class_<PyMapExport>(m, "MapExport",
                          "The whole map of a run: every used scan, undistorted, at its pose, one centroid "
                          "(with the mean intensity) per cell of resolution_m; with a spill folder only the "
                          "tiles around the sensor stay in memory. Calls from several threads run one at a time.")
      .def(nb::init<double, const Config&, const std::string&>(), "resolution_m"_a, "config"_a, "spill_dir"_a = "",
           "spill_dir: a folder where tiles of map.export_tile_m the sensor has left wait until the end "
           "(memory bounded by the tiles around the sensor); '': all in memory")
      .def(
          "add",
          [](PyMapExport& e, const Scan& scan, const pipeline::FrameResult& r) {
            return locked(e, [&](PyMapExport& x) { return x.map.add(scan, r.motion, r.undistorted, r.pose); });
          },
          "scan"_a, "result"_a, nb::call_guard<nb::gil_scoped_release>(),
          "Adds a processed scan at its pose with the motion it was undistorted with; returns the points added.")
      .def(
          "add",
          [](PyMapExport& e, const Scan& scan, const pipeline::FrameResult& r, const SE3& pose) {
            return locked(e, [&](PyMapExport& x) { return x.map.add(scan, r.motion, r.undistorted, pose); });
          },
          "scan"_a, "result"_a, "pose"_a, nb::call_guard<nb::gil_scoped_release>(),
          "Adds a processed scan undistorted with the motion of its result, placed at `pose` (the LiDAR pose at "
          "the scan end in this map's frame: a keyframe's submap, a corrected trajectory); returns the points added.")
      .def(
          "points", [](PyMapExport& e) { return locked(e, [](PyMapExport& x) { return x.map.points(); }); },
          nb::call_guard<nb::gil_scoped_release>(),
          "The whole map as one Scan (in memory): one point per cell (centroid, mean intensity).")
      .def(
          "write",
          [](PyMapExport& e, const std::vector<std::filesystem::path>& paths) {
            locked(e, [&](PyMapExport& x) {
              std::vector<io::PointStreamWriter> writers;
              writers.reserve(paths.size());
              for (const auto& p : paths) writers.emplace_back(p, x.map.cells());
              x.map.for_each_piece([&](std::span<const Vec3f> points, std::span<const float> intensity) {
                for (auto& w : writers) w.append(points, intensity);
              });
              for (auto& w : writers) w.close();
            });
          },
          "paths"_a, nb::call_guard<nb::gil_scoped_release>(),
          "Streams the whole map, tile by tile, into each file (.pcd binary or .ply binary; x y z intensity).")
      .def_prop_ro("cells", [](PyMapExport& e) { return locked(e, [](PyMapExport& x) { return x.map.cells(); }); })
      .def_prop_ro("cells_in_memory",
                   [](PyMapExport& e) { return locked(e, [](PyMapExport& x) { return x.map.cells_in_memory(); }); })
      .def_prop_ro("tiles_on_disk",
                   [](PyMapExport& e) { return locked(e, [](PyMapExport& x) { return x.map.tiles_on_disk(); }); })
      .def_prop_ro("points_added",
                   [](PyMapExport& e) { return locked(e, [](PyMapExport& x) { return x.map.points_added(); }); })
      .def_prop_ro("resolution_m", [](PyMapExport& e) { return e.map.resolution_m(); })
      .def_prop_ro("memory_bytes",
                   [](PyMapExport& e) { return locked(e, [](PyMapExport& x) { return x.map.memory_bytes(); }); });
}

}  // namespace farlio::python
