// Bindings of farlio::io: point cloud files, trajectory files and the sequence folder.
// Paths are str or os.PathLike; bad input raises farlio._core.InputError (a ValueError).
#include <nanobind/eigen/dense.h>
#include <nanobind/stl/filesystem.h>
#include <nanobind/stl/map.h>
#include <nanobind/stl/optional.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/vector.h>

#include "bindings.hpp"
#include "farlio/io/calibration.hpp"
#include "farlio/io/point_cloud_io.hpp"
#include "farlio/io/point_times.hpp"
#include "farlio/io/rigid_transform.hpp"
#include "farlio/io/sequence.hpp"
#include "farlio/io/trajectory_io.hpp"
#include "repr.hpp"

namespace nb = nanobind;
using namespace nb::literals;

namespace farlio::python {
namespace {

using namespace farlio::io;
using Path = std::filesystem::path;

PcdEncoding encoding_from(const std::string& name) {
  const auto enc = parse_pcd_encoding(name);
  if (!enc) throw nb::value_error(("unknown PCD encoding '" + name + "' (ascii, binary or binary_compressed)").c_str());
  return *enc;
}

TrajectoryFormat format_from(const std::string& name) {
  const auto format = parse_trajectory_format(name);
  if (format) return *format;
  std::string names;
  for (const auto& entry : kTrajectoryFormatNames) names += (names.empty() ? "" : ", ") + std::string(entry.first);
  throw nb::value_error(("unknown trajectory format '" + name + "'; use one of " + names).c_str());
}

/// Calls read(&warnings) and issues each warning as a Python UserWarning (the CLI prints them as
/// "farlio: warning: ..."); a warnings filter that turns them into errors raises.
template <class Read>
auto with_python_warnings(Read&& read) {
  Warnings warnings;
  auto result = read(&warnings);
  for (const auto& w : warnings) {
    if (PyErr_WarnEx(PyExc_UserWarning, w.c_str(), 1) != 0) throw nb::python_error();
  }
  return result;
}

nb::tuple trajectory_format_names() {
  nb::list names;
  for (const auto& entry : kTrajectoryFormatNames) names.append(nb::str(entry.first.data(), entry.first.size()));
  return nb::tuple(names);
}

std::string calibration_repr(const Calibration& c) {
  Repr r("Calibration");
  if (c.T_imu_lidar_by_name.empty()) {
    r.field("T_imu_lidar", c.T_imu_lidar);
  } else {
    r.field("T_imu_lidar_by_name", c.T_imu_lidar_by_name);
  }
  r.field("gravity_m_s2", c.gravity_m_s2).field("imu_rate_hz", c.imu_rate_hz).field("lidar_rate_hz", c.lidar_rate_hz);
  if (!c.source.empty()) r.field("source", c.source.string());
  return r.str();
}

void bind_point_clouds(nb::module_& m) {
  m.def("read_point_cloud", &read_point_cloud, "path"_a,
        "Reads a .pcd/.ply/.bin file (optionally .gz) into a Scan (stamps 0).");
  m.def(
      "write_pcd",
      [](const Path& path, const Scan& scan, const std::string& encoding) {
        write_pcd(path, scan, encoding_from(encoding));
      },
      "path"_a, "scan"_a, "encoding"_a = "binary",
      "Writes x y z [intensity] [t] float32 [sensor_id] uint8; encoding ascii, binary or binary_compressed.");
  m.def(
      "write_ply",
      [](const Path& path, const Scan& scan) {
        write_ply(path, scan.points, scan.intensity.empty() ? nullptr : &scan.intensity);
      },
      "path"_a, "scan"_a, "Binary little endian PLY of the scan's points (and intensity if present).");
  m.def("write_kitti_bin", &write_kitti_bin, "path"_a, "scan"_a, "KITTI .bin: float32 x y z intensity.");
  m.attr("MAX_SCAN_SPAN_S") = kMaxScanSpan_s;
  m.def("point_time_span_plausible", &point_time_span_plausible, "span_s"_a,
        "Whether per-point times spanning span_s seconds can belong to one scan (finite, at most MAX_SCAN_SPAN_S).");
  m.def("check_point_times", &check_point_times, "scan"_a, "what"_a,
        "InputError '<what>: <problem>' when the scan's per-point times cannot be seconds since its start: a span "
        "over MAX_SCAN_SPAN_S (a unit read wrong), times before the start or past its duration (end - start).");
}

void bind_trajectories(nb::module_& m) {
  m.def(
      "read_tum", [](const Path& path) { return with_python_warnings([&](Warnings* w) { return read_tum(path, w); }); },
      "path"_a, "A TUM file; a torn last line (no newline, does not parse) is skipped with a UserWarning.");
  m.def("write_tum", &write_tum, "path"_a, "trajectory"_a);
  m.def(
      "read_kitti",
      [](const Path& path, const std::optional<std::vector<std::int64_t>>& stamps_ns) {
        return with_python_warnings(
            [&](Warnings* w) { return read_kitti(path, stamps_ns ? &*stamps_ns : nullptr, w); });
      },
      "path"_a, "stamps_ns"_a = nb::none(),
      "KITTI 3x4 poses; without stamps pose i gets i * 100 ms. A torn last line is skipped with a UserWarning.");
  m.def("write_kitti", &write_kitti, "path"_a, "trajectory"_a);
  m.def(
      "read_stamps",
      [](const Path& path) { return with_python_warnings([&](Warnings* w) { return read_stamps(path, w); }); },
      "path"_a,
      "A times file: the first field of each line, seconds -> integer ns (exact for plain decimals); a torn last "
      "line is skipped with a UserWarning.");
  m.attr("TRAJECTORY_FORMATS") = trajectory_format_names();
  m.def(
      "read_trajectory",
      [](const Path& path, const std::string& format, const std::optional<Path>& times) {
        const TrajectoryFormat f = format_from(format);
        return with_python_warnings([&](Warnings* w) { return read_trajectory(path, f, times, w); });
      },
      "path"_a, "format"_a = "auto", "times"_a = nb::none(),
      "A TUM or KITTI file ('auto': by the column count, 8 or 12); KITTI poses are stamped from the times "
      "file (read_stamps), without one pose i gets i * 100 ms. A torn last line (no newline, does not parse) "
      "is skipped with a UserWarning naming the file and line.");
  nb::class_<TrajectoryWriter>(m, "TrajectoryWriter", "Appends TUM (or KITTI) lines, flushing each one.")
      .def(
          "__init__",
          [](TrajectoryWriter* w, const Path& path, const std::string& format) {
            const auto f = parse_trajectory_format(format);
            if (!f || *f == TrajectoryFormat::kAuto)
              throw nb::value_error("TrajectoryWriter: format must be tum or kitti");
            new (w) TrajectoryWriter(path, *f);
          },
          "path"_a, "format"_a = "tum")
      .def("append", &TrajectoryWriter::append, "stamp_ns"_a, "pose"_a)
      .def("__len__", &TrajectoryWriter::size)
      .def_prop_ro("path", &TrajectoryWriter::path);
}

void bind_sequence(nb::module_& m) {
  nb::class_<Calibration>(m, "Calibration", "calib.yaml: extrinsic(s), gravity, sensor rates.")
      .def(nb::init<>())
      .def_rw("T_imu_lidar", &Calibration::T_imu_lidar, "one LiDAR: maps its points into the IMU (body) frame")
      .def_rw("T_imu_lidar_by_name", &Calibration::T_imu_lidar_by_name,
              "several LiDARs: {topic or frame id: T_imu_lidar} (a copy); empty for one LiDAR")
      .def_rw("gravity_m_s2", &Calibration::gravity_m_s2, "None when the file does not state it")
      .def_rw("imu_rate_hz", &Calibration::imu_rate_hz)
      .def_rw("lidar_rate_hz", &Calibration::lidar_rate_hz)
      .def_rw("source", &Calibration::source, "the file it was read from")
      .def("gravity_or_default", &Calibration::gravity_or_default, "gravity_m_s2, or 9.81 when not stated")
      .def("lidar_extrinsic", &Calibration::lidar_extrinsic, "names"_a,
           "T_imu_lidar of the LiDAR known by any of names (topic, frame id); InputError naming the entries "
           "when the mapping has none of them.")
      .def("__repr__", &calibration_repr);
  m.def("read_calibration", &read_calibration, "path"_a);
  m.def("write_calibration", &write_calibration, "path"_a, "calibration"_a);
  m.def("rigid_transform_from_matrix", &rigid_transform_from_matrix, "m"_a, "what"_a,
        "The SE3 of a 4x4 matrix if it is rigid (finite, rotation orthonormal, last row 0 0 0 1, within the "
        "tolerance of calib.yaml); else InputError '<what>: not a rigid transform: <why>'.");

  nb::class_<SequenceReader>(m, "SequenceReader", "Reads a sequence folder (lidar/, imu.csv, calib.yaml, ...).")
      .def(nb::init<Path>(), "dir"_a)
      .def_prop_ro("dir", &SequenceReader::dir)
      .def("num_scans", &SequenceReader::num_scans)
      .def("__len__", &SequenceReader::num_scans)
      .def("scan_end_stamp_ns", &SequenceReader::scan_end_stamp_ns, "i"_a)
      .def("scan_start_stamp_ns", &SequenceReader::scan_start_stamp_ns, "i"_a)
      .def("scan_path", &SequenceReader::scan_path, "i"_a)
      .def("read_scan", &SequenceReader::read_scan, "i"_a)
      .def("has_imu", &SequenceReader::has_imu)
      .def("imu", &SequenceReader::imu, "The IMU samples (a copy).")
      .def("has_calibration", &SequenceReader::has_calibration)
      .def("calibration", &SequenceReader::calibration)
      .def("groundtruth", &SequenceReader::groundtruth)
      .def("groundtruth_scans", &SequenceReader::groundtruth_scans)
      .def("warnings", &SequenceReader::warnings);

  nb::class_<SequenceWriter>(m, "SequenceWriter", "Writes a sequence folder, one whole file per call.")
      .def(nb::init<Path>(), "dir"_a)
      .def_prop_ro("dir", &SequenceWriter::dir)
      .def("write_calibration", &SequenceWriter::write_calibration, "calibration"_a)
      .def(
          "write_scan",
          [](SequenceWriter& w, const Scan& scan, const std::string& encoding) {
            w.write_scan(scan, encoding_from(encoding));
          },
          "scan"_a, "encoding"_a = "binary")
      .def("write_imu", &SequenceWriter::write_imu, "samples"_a)
      .def("write_groundtruth", &SequenceWriter::write_groundtruth, "body_poses"_a)
      .def("write_groundtruth_scans", &SequenceWriter::write_groundtruth_scans, "body_poses_at_scan_end"_a)
      .def("write_groundtruth_kitti", &SequenceWriter::write_groundtruth_kitti, "lidar_poses_at_scan_end"_a)
      .def("write_kitti_scan", &SequenceWriter::write_kitti_scan, "scan"_a, "index"_a)
      .def("write_kitti_times", &SequenceWriter::write_kitti_times, "scan_stamps_ns"_a)
      .def("write_meta", &SequenceWriter::write_meta, "meta"_a);
}

}  // namespace

void bind_io(nb::module_& m) {
  bind_point_clouds(m);
  bind_trajectories(m);
  bind_sequence(m);
}

}  // namespace farlio::python
