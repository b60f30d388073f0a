#include "farlio/io/imu_csv.hpp"

#include <array>
#include <cmath>
#include <fstream>
#include <optional>
#include <stdexcept>
#include <string_view>
#include <utility>

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

/// A parsed sample and the line it came from.
struct Row {
  ImuSample sample;
  std::size_t line = 0;
};

/// Keeps the samples in time order as they are read. A sample that is not after the last one kept
/// conflicts with it, and the sample after both decides which of the two is out of place: one
/// stamped ahead of the rest (a far-future stamp) is dropped, not every sample after it; one
/// stamped behind is dropped. Each dropped sample is named in a warning.
class TimeOrder {
 public:
  TimeOrder(const std::string& file, std::vector<std::string>& warnings) : file_(file), warnings_(warnings) {}

  void add(const Row& row) {
    if (conflict_) {
      const Row c = *std::exchange(conflict_, std::nullopt);
      const std::int64_t t = c.sample.stamp_ns, next = row.sample.stamp_ns;
      const bool next_follows = next > t && next <= kept_.back().stamp_ns;
      const bool after_the_one_before = kept_.size() < 2 || t > kept_[kept_.size() - 2].stamp_ns;
      if (next_follows && after_the_one_before) {  // the last one kept was stamped ahead
        drop({kept_.back(), last_line_}, "is ahead of the samples after it (" + std::to_string(t) + " ns next)");
        kept_.back() = c.sample;
        last_line_ = c.line;
      } else {
        drop(c, "is not after the previous one (" + std::to_string(kept_.back().stamp_ns) + " ns)");
      }
    }
    if (kept_.empty() || row.sample.stamp_ns > kept_.back().stamp_ns) {
      kept_.push_back(row.sample);
      last_line_ = row.line;
    } else {
      conflict_ = row;
    }
  }

  /// The samples kept (a conflict left at the end is dropped).
  std::vector<ImuSample> finish() {
    if (conflict_) drop(*conflict_, "is not after the previous one (" + std::to_string(kept_.back().stamp_ns) + " ns)");
    return std::move(kept_);
  }

 private:
  void drop(const Row& r, const std::string& why) {
    warnings_.push_back(file_ + ":" + std::to_string(r.line) + ": sample at " + std::to_string(r.sample.stamp_ns) +
                        " ns " + why + "; dropped");
  }

  const std::string& file_;
  std::vector<std::string>& warnings_;
  std::vector<ImuSample> kept_;
  std::size_t last_line_ = 0;
  std::optional<Row> conflict_;
};

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

  TimeOrder samples(file, warnings);
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
    samples.add({s, line_no});
  }
  if (non_finite_samples > kNamedNonFiniteSamples) {
    warnings.push_back(file + ": " + std::to_string(non_finite_samples) +
                       " samples with a nan or inf value dropped in all (the first " +
                       std::to_string(kNamedNonFiniteSamples) + " named above)");
  }
  return samples.finish();
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
