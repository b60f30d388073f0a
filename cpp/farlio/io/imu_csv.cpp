#include "farlio/io/imu_csv.hpp"

#include <array>
#include <cmath>
#include <fstream>
#include <optional>
#include <stdexcept>
#include <string_view>

#include "farlio/core/error.hpp"
#include "farlio/io/file_bytes.hpp"
#include "farlio/io/text_number.hpp"

namespace farlio::io {
namespace {

constexpr std::array<std::string_view, 7> kColumns = {"t_ns", "gx", "gy", "gz", "ax", "ay", "az"};
constexpr std::size_t kStampColumn = 0;
constexpr std::size_t kGyroColumn = 1;
constexpr std::size_t kAccelColumn = 4;
constexpr std::size_t kAxes = 3;
/// Samples with a nan or inf value are named one by one up to this many, then counted.
constexpr std::size_t kNamedNonFiniteSamples = 10;

std::vector<std::string_view> split_commas(std::string_view line) {
  std::vector<std::string_view> out;
  std::size_t start = 0;
  for (;;) {
    const auto comma = line.find(',', start);
    out.push_back(trim(line.substr(start, comma == std::string_view::npos ? std::string_view::npos : comma - start)));
    if (comma == std::string_view::npos) break;
    start = comma + 1;
  }
  return out;
}

}  // namespace

std::vector<ImuSample> read_imu_csv(const std::filesystem::path& path, std::vector<std::string>& warnings) {
  const std::string file = path.string();
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) throw InputError(file + ": no such file");
  std::ifstream in(path);
  if (!in) throw InputError(file + ": cannot open file");
  return parse_imu_csv(in, file, warnings);
}

std::vector<ImuSample> parse_imu_csv(std::istream& in, const std::string& file, std::vector<std::string>& warnings) {
  std::string line;
  std::size_t line_no = 0;
  // Header: the first non-blank line.
  std::vector<std::string_view> header;
  std::string header_line;
  while (header.empty() && std::getline(in, header_line)) {
    ++line_no;
    if (!trim(header_line).empty()) header = split_commas(trim(header_line));
  }
  if (header.empty()) throw InputError(file + ": empty file (expected header t_ns,gx,gy,gz,ax,ay,az)");
  std::array<std::size_t, kColumns.size()> col{};
  for (std::size_t c = 0; c < kColumns.size(); ++c) {
    std::optional<std::size_t> found;
    for (std::size_t k = 0; k < header.size(); ++k) {
      if (header[k] == kColumns[c]) found = k;
    }
    if (!found) throw InputError(file + ": header lacks column '" + std::string(kColumns[c]) + "'");
    col[c] = *found;
  }
  for (auto name : header) {
    bool known = false;
    for (auto c : kColumns) known = known || name == c;
    if (!known) warnings.push_back(file + ": unknown column '" + std::string(name) + "' ignored");
  }

  std::vector<ImuSample> samples;
  std::size_t non_finite_samples = 0;
  while (std::getline(in, line)) {
    ++line_no;
    const auto t = trim(line);
    if (t.empty()) continue;
    const auto fields = split_commas(t);
    const std::string where = file + ":" + std::to_string(line_no);
    if (fields.size() != header.size()) {
      throw InputError(where + ": " + std::to_string(fields.size()) + " fields, the header has " +
                       std::to_string(header.size()));
    }
    ImuSample s;
    const auto stamp = parse_int64(fields[col[kStampColumn]]);
    if (!stamp) throw InputError(where + ": t_ns '" + std::string(fields[col[kStampColumn]]) + "' is not an integer");
    s.stamp_ns = *stamp;
    std::string non_finite;  // the first column that reads nan or inf
    for (std::size_t axis = 0; axis < kAxes; ++axis) {
      for (std::size_t base : {kGyroColumn, kAccelColumn}) {
        const auto tok = fields[col[base + axis]];
        const auto v = parse_double(tok);
        if (!v) {
          throw InputError(where + ": " + std::string(kColumns[base + axis]) + " '" + std::string(tok) +
                           "' is not a number");
        }
        if (!std::isfinite(*v) && non_finite.empty()) {
          non_finite = std::string(kColumns[base + axis]) + " '" + std::string(tok) + "'";
        }
        (base == kGyroColumn ? s.gyro_rad_s : s.accel_m_s2)[static_cast<Eigen::Index>(axis)] = *v;
      }
    }
    if (!non_finite.empty()) {  // a sensor's NaN: the sample is dropped, the recording stays usable
      if (++non_finite_samples <= kNamedNonFiniteSamples) {
        warnings.push_back(where + ": " + non_finite + " is not finite; sample dropped");
      }
      continue;
    }
    if (!samples.empty() && s.stamp_ns <= samples.back().stamp_ns) {
      warnings.push_back(where + ": sample at " + std::to_string(s.stamp_ns) + " ns is not after the previous one (" +
                         std::to_string(samples.back().stamp_ns) + " ns); dropped");
      continue;
    }
    samples.push_back(s);
  }
  if (non_finite_samples > kNamedNonFiniteSamples) {
    warnings.push_back(file + ": " + std::to_string(non_finite_samples) +
                       " samples with a nan or inf value dropped in all (the first " +
                       std::to_string(kNamedNonFiniteSamples) + " named above)");
  }
  return samples;
}

void write_imu_csv(const std::filesystem::path& path, const std::vector<ImuSample>& samples) {
  std::string text = "t_ns,gx,gy,gz,ax,ay,az\n";
  for (const auto& s : samples) {
    text += std::to_string(s.stamp_ns);
    for (const auto& v : {s.gyro_rad_s, s.accel_m_s2}) {
      for (Eigen::Index k = 0; k < v.size(); ++k) {
        text += ',';
        text += format_number(v[k]);
      }
    }
    text += '\n';
  }
  write_text_file(path, text);
}

}  // namespace farlio::io
