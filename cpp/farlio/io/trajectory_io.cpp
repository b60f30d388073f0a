#include "farlio/io/trajectory_io.hpp"

#include <array>
#include <cmath>
#include <fstream>
#include <iostream>
#include <stdexcept>
#include <string>
#include <type_traits>

#include "farlio/core/error.hpp"
#include "farlio/io/file_bytes.hpp"
#include "farlio/io/text_number.hpp"

namespace farlio::io {
namespace {

constexpr std::size_t kTumValues = 8;     // t x y z qx qy qz qw
constexpr std::size_t kKittiValues = 12;  // 3x4 row-major
constexpr int kKittiRows = 3;
constexpr int kKittiCols = 4;
constexpr double kMinQuaternionNorm = 1e-6;
constexpr char kFieldComma = ',';  // times files may be comma separated
constexpr const char* kTumHeader = "# t x y z qx qy qz qw (t in seconds)\n";

std::string tum_line(std::int64_t stamp_ns, const SE3& pose) {
  const auto& t = pose.translation();
  const auto& q = pose.quaternion();
  std::string s = format_seconds_from_ns(stamp_ns);
  for (double v : {t.x(), t.y(), t.z(), q.x(), q.y(), q.z(), q.w()}) {
    s += ' ';
    s += format_number(v);
  }
  s += '\n';
  return s;
}

/// The 3x4 row-major [R | t] of a KITTI line.
std::string kitti_line(const SE3& pose) {
  const Mat4d m = pose.matrix();
  std::string s;
  for (int r = 0; r < kKittiRows; ++r) {
    for (int c = 0; c < kKittiCols; ++c) {
      if (r || c) s += ' ';
      s += format_number(m(r, c));
    }
  }
  s += '\n';
  return s;
}

std::ifstream open_for_reading(const std::filesystem::path& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) throw InputError(path.string() + ": no such file");
  std::ifstream in(path);
  if (!in) throw InputError(path.string() + ": cannot open file");
  return in;
}

void warn(Warnings* warnings, const std::string& message) {
  if (warnings != nullptr) {
    warnings->push_back(message);
  } else {
    std::cerr << "farlio: warning: " << message << '\n';
  }
}

/// Calls on_values(line_no, tokens) for every non-blank, non-comment line; stops early when
/// on_values returns false (if it returns a bool). An InputError from the last line when it has
/// no newline (a torn write) becomes a warning and the line is skipped; returns whether that
/// happened.
template <class F>
bool for_each_data_line(std::istream& in, const std::string& file, Warnings* warnings, F&& on_values) {
  std::string line;
  std::size_t line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    const auto t = trim(line);
    if (t.empty() || t.front() == '#') continue;
    try {
      if constexpr (std::is_same_v<decltype(on_values(line_no, split_whitespace(t))), bool>) {
        if (!on_values(line_no, split_whitespace(t))) return false;
      } else {
        on_values(line_no, split_whitespace(t));
      }
    } catch (const InputError& e) {
      if (!in.eof()) throw;  // the line ended with a newline: it was written whole
      warn(warnings, file + ":" + std::to_string(line_no) +
                         ": last line skipped: it has no newline and does not parse (a write cut short?): " + e.what());
      return true;
    }
  }
  return false;
}

[[noreturn]] void bad_line(const std::string& file, std::size_t line_no, const std::string& what) {
  throw InputError(file + ":" + std::to_string(line_no) + ": " + what);
}

double number_at(const std::string& file, std::size_t line_no, std::string_view tok) {
  const auto v = parse_double(tok);
  if (!v || !std::isfinite(*v)) bad_line(file, line_no, "'" + std::string(tok) + "' is not a finite number");
  return *v;
}

}  // namespace

Trajectory parse_tum(std::istream& in, const std::string& file, Warnings* warnings) {
  Trajectory traj;
  for_each_data_line(in, file, warnings, [&](std::size_t line_no, const std::vector<std::string_view>& tok) {
    if (tok.size() != kTumValues) {
      bad_line(file, line_no, "expected 8 values 't x y z qx qy qz qw', found " + std::to_string(tok.size()));
    }
    const auto stamp = parse_seconds_to_ns(tok[0]);
    if (!stamp) bad_line(file, line_no, "time '" + std::string(tok[0]) + "' is not a number of seconds");
    std::array<double, kTumValues - 1> v{};
    for (std::size_t k = 1; k < kTumValues; ++k) v[k - 1] = number_at(file, line_no, tok[k]);
    const Eigen::Quaterniond q(v[6], v[3], v[4], v[5]);
    if (q.norm() < kMinQuaternionNorm) bad_line(file, line_no, "quaternion has zero norm");
    traj.push_back(*stamp, SE3(q, Eigen::Vector3d(v[0], v[1], v[2])));
  });
  return traj;
}

Trajectory read_tum(const std::filesystem::path& path, Warnings* warnings) {
  std::ifstream in = open_for_reading(path);
  return parse_tum(in, path.string(), warnings);
}

void write_tum(const std::filesystem::path& path, const Trajectory& trajectory) {
  std::string text = kTumHeader;
  for (const auto& p : trajectory) text += tum_line(p.stamp_ns, p.pose);
  write_text_file(path, text);
}

Trajectory parse_kitti(std::istream& in, const std::string& file, const std::vector<std::int64_t>* stamps_ns,
                       Warnings* warnings) {
  std::vector<SE3> poses;
  const bool torn =
      for_each_data_line(in, file, warnings, [&](std::size_t line_no, const std::vector<std::string_view>& tok) {
        if (tok.size() != kKittiValues) {
          bad_line(file, line_no, "expected 12 values (3x4 row-major), found " + std::to_string(tok.size()));
        }
        Mat4d m = Mat4d::Identity();
        for (int r = 0; r < kKittiRows; ++r) {
          for (int c = 0; c < kKittiCols; ++c)
            m(r, c) = number_at(file, line_no, tok[static_cast<std::size_t>(r * kKittiCols + c)]);
        }
        poses.push_back(SE3::from_matrix(m));
      });
  // The times file may still hold the stamp of the pose whose line was torn.
  const bool stamps_match =
      stamps_ns == nullptr || stamps_ns->size() == poses.size() || (torn && stamps_ns->size() == poses.size() + 1);
  if (!stamps_match) {
    throw InputError(file + ": " + std::to_string(poses.size()) + " poses but " + std::to_string(stamps_ns->size()) +
                     " stamps were given");
  }
  Trajectory traj;
  for (std::size_t i = 0; i < poses.size(); ++i) {
    const std::int64_t stamp = stamps_ns ? (*stamps_ns)[i] : static_cast<std::int64_t>(i) * kKittiDefaultPeriodNs;
    traj.push_back(stamp, poses[i]);
  }
  return traj;
}

Trajectory read_kitti(const std::filesystem::path& path, const std::vector<std::int64_t>* stamps_ns,
                      Warnings* warnings) {
  std::ifstream in = open_for_reading(path);
  return parse_kitti(in, path.string(), stamps_ns, warnings);
}

std::vector<std::int64_t> parse_stamps(std::istream& in, const std::string& file, Warnings* warnings) {
  std::vector<std::int64_t> stamps;
  for_each_data_line(in, file, warnings, [&](std::size_t line_no, const std::vector<std::string_view>& tok) {
    const std::string_view first = tok[0].substr(0, tok[0].find(kFieldComma));
    const auto stamp = parse_seconds_to_ns(first);
    if (!stamp) bad_line(file, line_no, "'" + std::string(first) + "' is not a number of seconds");
    stamps.push_back(*stamp);
  });
  if (stamps.empty()) throw InputError(file + ": no stamps");
  return stamps;
}

std::vector<std::int64_t> read_stamps(const std::filesystem::path& path, Warnings* warnings) {
  std::ifstream in = open_for_reading(path);
  return parse_stamps(in, path.string(), warnings);
}

std::optional<TrajectoryFormat> parse_trajectory_format(std::string_view name) {
  for (const auto& [n, format] : kTrajectoryFormatNames) {
    if (n == name) return format;
  }
  return std::nullopt;
}

TrajectoryFormat detect_trajectory_format(const std::filesystem::path& path) {
  std::optional<TrajectoryFormat> format;
  std::ifstream in = open_for_reading(path);
  Warnings ignored;  // the reader that follows warns about a torn line
  const std::string file = path.string();
  for_each_data_line(in, file, &ignored, [&](std::size_t line_no, const std::vector<std::string_view>& tok) {
    if (tok.size() != kTumValues && tok.size() != kKittiValues) {
      bad_line(file, line_no,
               std::to_string(tok.size()) + " values is neither TUM (" + std::to_string(kTumValues) + ") nor KITTI (" +
                   std::to_string(kKittiValues) + ")");
    }
    format = tok.size() == kTumValues ? TrajectoryFormat::kTum : TrajectoryFormat::kKitti;
    return false;  // the first data line decides
  });
  if (!format) throw InputError(path.string() + ": no poses");
  return *format;
}

Trajectory read_trajectory(const std::filesystem::path& path, TrajectoryFormat format,
                           const std::optional<std::filesystem::path>& kitti_times, Warnings* warnings) {
  if (format == TrajectoryFormat::kAuto) format = detect_trajectory_format(path);
  if (format == TrajectoryFormat::kTum) return read_tum(path, warnings);
  if (!kitti_times) return read_kitti(path, nullptr, warnings);
  const std::vector<std::int64_t> stamps = read_stamps(*kitti_times, warnings);
  return read_kitti(path, &stamps, warnings);
}

void write_kitti(const std::filesystem::path& path, const Trajectory& trajectory) {
  std::string text;
  for (const auto& p : trajectory) text += kitti_line(p.pose);
  write_text_file(path, text);
}

TrajectoryWriter::TrajectoryWriter(const std::filesystem::path& path, TrajectoryFormat format)
    : out_(path), kitti_(format == TrajectoryFormat::kKitti) {
  if (format == TrajectoryFormat::kAuto) throw std::invalid_argument(path.string() + ": write TUM or KITTI, not auto");
  if (!kitti_) {
    out_.write(kTumHeader);
    out_.flush();
  }
}

void TrajectoryWriter::append(std::int64_t stamp_ns, const SE3& pose) {
  out_.write(kitti_ ? kitti_line(pose) : tum_line(stamp_ns, pose));
  out_.flush();
  ++count_;
}

}  // namespace farlio::io
