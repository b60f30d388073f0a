// Reading PCD v0.7 files: DATA ascii, binary (array of structures) and binary_compressed
// (uint32 compressed size, uint32 uncompressed size, LZF data of the fields one after another).
#include <cstdint>
#include <string>
#include <string_view>

#include "farlio/core/error.hpp"
#include "farlio/io/file_bytes.hpp"
#include "farlio/io/lzf.hpp"
#include "farlio/io/pcd_header.hpp"
#include "farlio/io/point_cloud_io.hpp"
#include "farlio/io/text_number.hpp"

namespace farlio::io {
namespace {

constexpr bool kLittleEndian = false;  // the `big_endian` argument of load_scalar
constexpr ScalarType kUint32{ScalarKind::Uint, sizeof(std::uint32_t)};
constexpr std::size_t kCompressedPrefixBytes = 2 * sizeof(std::uint32_t);

std::vector<std::size_t> field_offsets(const std::vector<FieldSpec>& fields, std::size_t scale) {
  std::vector<std::size_t> off;
  std::size_t o = 0;
  for (const auto& f : fields) {
    off.push_back(o);
    o += f.type.size_bytes * f.count * scale;
  }
  return off;
}

Scan read_ascii(ByteView bytes, const PcdHeader& h, const ChannelMap& m, const std::string& file) {
  std::size_t values_per_point = 0;
  for (const auto& f : h.fields) values_per_point += f.count;
  std::vector<std::size_t> column(h.fields.size());
  {
    std::size_t c = 0;
    for (std::size_t k = 0; k < h.fields.size(); ++k) {
      column[k] = c;
      c += h.fields[k].count;
    }
  }
  std::vector<double> values;
  std::size_t pos = h.data_offset;
  std::size_t line_no = h.header_lines;
  std::size_t got = 0;
  while (pos < bytes.size()) {
    std::size_t nl = pos;
    while (nl < bytes.size() && bytes[nl] != '\n') ++nl;
    const std::string_view line(reinterpret_cast<const char*>(bytes.data()) + pos, nl - pos);
    pos = nl + 1;
    ++line_no;
    const auto tokens = split_whitespace(line);
    if (tokens.empty()) continue;
    if (got == h.points) {
      throw InputError(file + ": header says " + std::to_string(h.points) + " points but line " +
                       std::to_string(line_no) + " holds another one");
    }
    if (tokens.size() != values_per_point) {
      throw InputError(file + ": line " + std::to_string(line_no) + " has " + std::to_string(tokens.size()) +
                       " values, expected " + std::to_string(values_per_point));
    }
    for (auto tok : tokens) {
      const auto v = parse_double(tok);
      if (!v)
        throw InputError(file + ": line " + std::to_string(line_no) + ": '" + std::string(tok) + "' is not a number");
      values.push_back(*v);
    }
    ++got;
  }
  if (got != h.points) {
    throw InputError(file + ": header says " + std::to_string(h.points) + " points but data holds " +
                     std::to_string(got) + " (truncated?)");
  }
  return assemble_scan(h.points, m, file,
                       [&](std::size_t i, std::size_t k) { return values[i * values_per_point + column[k]]; });
}

Scan read_binary(ByteView bytes, const PcdHeader& h, const ChannelMap& m, const std::string& file) {
  const std::size_t record = h.record_bytes;  // > 0: every field has SIZE >= 1 and COUNT >= 1
  const std::size_t available = bytes.size() - h.data_offset;
  const std::size_t needed = h.data_bytes;
  if (available < needed) {
    throw InputError(file + ": header says " + std::to_string(h.points) + " points but data holds " +
                     std::to_string(available / record) + " (truncated?)");
  }
  if (available > needed) {
    throw InputError(file + ": data holds " + std::to_string(available - needed) + " bytes more than the " +
                     std::to_string(h.points) + " points the header announces");
  }
  const auto off = field_offsets(h.fields, 1);
  const unsigned char* base = bytes.data() + h.data_offset;
  return assemble_scan(h.points, m, file, [&](std::size_t i, std::size_t k) {
    return load_scalar(base + i * record + off[k], h.fields[k].type, kLittleEndian);
  });
}

Scan read_binary_compressed(ByteView bytes, const PcdHeader& h, const ChannelMap& m, const std::string& file) {
  const std::size_t available = bytes.size() - h.data_offset;
  if (available < kCompressedPrefixBytes) {
    throw InputError(file + ": binary_compressed data lacks its 8-byte size prefix (truncated?)");
  }
  const unsigned char* base = bytes.data() + h.data_offset;
  const auto compressed = static_cast<std::size_t>(load_scalar(base, kUint32, kLittleEndian));
  const auto uncompressed = static_cast<std::size_t>(load_scalar(base + sizeof(std::uint32_t), kUint32, kLittleEndian));
  const std::size_t needed = h.data_bytes;
  if (uncompressed != needed) {
    throw InputError(file + ": header says " + std::to_string(h.points) + " points (" + std::to_string(needed) +
                     " bytes) but the compressed block expands to " + std::to_string(uncompressed) + " bytes");
  }
  if (compressed > available - kCompressedPrefixBytes) {
    throw InputError(file + ": compressed block of " + std::to_string(compressed) + " bytes but only " +
                     std::to_string(available - kCompressedPrefixBytes) + " bytes follow (truncated?)");
  }
  std::vector<unsigned char> raw;
  try {
    raw = lzf_decompress({base + kCompressedPrefixBytes, compressed}, uncompressed);
  } catch (const LzfError& e) {
    throw InputError(file + ": corrupt binary_compressed data: " + e.what());
  }
  const auto off = field_offsets(h.fields, h.points);  // structure of arrays
  return assemble_scan(h.points, m, file, [&](std::size_t i, std::size_t k) {
    const auto& f = h.fields[k];
    return load_scalar(raw.data() + off[k] + i * f.count * f.type.size_bytes, f.type, kLittleEndian);
  });
}

}  // namespace

Scan read_pcd(const std::filesystem::path& path) { return parse_pcd(read_file_bytes(path), path.string()); }

Scan parse_pcd(ByteView bytes, const std::string& file) {
  const PcdHeader h = parse_pcd_header(bytes, file);
  const ChannelMap m = map_channels(h.fields, file);
  switch (h.encoding) {
    case PcdEncoding::Ascii: return read_ascii(bytes, h, m, file);
    case PcdEncoding::Binary: return read_binary(bytes, h, m, file);
    case PcdEncoding::BinaryCompressed: return read_binary_compressed(bytes, h, m, file);
  }
  return {};
}

}  // namespace farlio::io
