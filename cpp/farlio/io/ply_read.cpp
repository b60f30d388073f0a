// Reading PLY files (ascii 1.0, binary_little_endian 1.0, binary_big_endian 1.0). The "vertex"
// element gives the points; every other element (faces, edges, ...) is skipped, before or after it.
#include <cmath>
#include <string>
#include <string_view>

#include "farlio/core/error.hpp"
#include "farlio/io/file_bytes.hpp"
#include "farlio/io/point_cloud_io.hpp"
#include "farlio/io/point_fields.hpp"
#include "farlio/io/size_limits.hpp"
#include "farlio/io/text_number.hpp"

namespace farlio::io {
namespace {

enum class PlyFormat { Ascii, BinaryLittle, BinaryBig };

struct PlyProperty {
  std::string name;
  ScalarType type;
  bool is_list = false;
  ScalarType count_type;  ///< type of a list's length
};

struct PlyElement {
  std::string name;
  std::size_t count = 0;
  std::vector<PlyProperty> properties;
};

struct PlyHeader {
  PlyFormat format = PlyFormat::Ascii;
  std::vector<PlyElement> elements;
  std::size_t data_offset = 0;
};

constexpr std::string_view kVertex = "vertex";
constexpr std::size_t kMaxListLength = std::size_t{1} << 20;  // a sanity bound on corrupt counts

PlyHeader parse_header(ByteView bytes, const std::string& file) {
  PlyHeader h;
  std::size_t pos = 0;
  std::size_t line_no = 0;
  bool format_seen = false;
  auto fail = [&](const std::string& what) -> void {
    throw InputError(file + ": header line " + std::to_string(line_no) + ": " + what);
  };
  auto type_of = [&](std::string_view name) {
    const auto t = ply_scalar_type(std::string(name));
    if (!t) fail("unknown property type '" + std::string(name) + "'");
    return *t;
  };
  for (;;) {
    if (pos >= bytes.size()) throw InputError(file + ": header ends without end_header (truncated or not a PLY file?)");
    std::size_t nl = pos;
    while (nl < bytes.size() && bytes[nl] != '\n') ++nl;
    const std::string_view line(reinterpret_cast<const char*>(bytes.data()) + pos, nl - pos);
    pos = nl + 1;
    ++line_no;
    const auto tok = split_whitespace(line);
    if (line_no == 1) {
      if (tok.size() != 1 || tok[0] != "ply") throw InputError(file + ": not a PLY file (first line is not 'ply')");
      continue;
    }
    if (tok.empty()) continue;
    const std::string_view key = tok[0];
    if (key == "comment" || key == "obj_info") continue;
    if (key == "end_header") break;
    if (key == "format") {
      if (tok.size() != 3 || tok[2] != "1.0") fail("expected 'format <type> 1.0'");
      if (tok[1] == "ascii")
        h.format = PlyFormat::Ascii;
      else if (tok[1] == "binary_little_endian")
        h.format = PlyFormat::BinaryLittle;
      else if (tok[1] == "binary_big_endian")
        h.format = PlyFormat::BinaryBig;
      else
        fail("unknown format '" + std::string(tok[1]) + "'");
      format_seen = true;
    } else if (key == "element") {
      if (tok.size() != 3) fail("expected 'element <name> <count>'");
      const auto n = parse_int64(tok[2]);
      if (!n || *n < 0) fail("element count '" + std::string(tok[2]) + "' is not a non-negative integer");
      const auto count = static_cast<std::size_t>(*n);
      require_within_limit(count, kMaxCloudPoints, file,
                           "header line " + std::to_string(line_no) + ": count " + std::to_string(count) +
                               " of element '" + std::string(tok[1]) + "'");
      h.elements.push_back({std::string(tok[1]), count, {}});
    } else if (key == "property") {
      if (h.elements.empty()) fail("property before any element");
      PlyProperty p;
      if (tok.size() == 5 && tok[1] == "list") {
        p.is_list = true;
        p.count_type = type_of(tok[2]);
        if (!p.count_type.is_integer()) fail("list length type must be an integer type");
        p.type = type_of(tok[3]);
        p.name = tok[4];
      } else if (tok.size() == 3) {
        p.type = type_of(tok[1]);
        p.name = tok[2];
      } else {
        fail("expected 'property <type> <name>' or 'property list <type> <type> <name>'");
      }
      h.elements.back().properties.push_back(p);
    } else {
      fail("unknown keyword '" + std::string(key) + "'");
    }
  }
  if (!format_seen) throw InputError(file + ": header has no format line");
  h.data_offset = std::min(pos, bytes.size());
  return h;
}

/// Sequential reader of scalars from the data section, ascii tokens or binary bytes.
class PlyCursor {
 public:
  PlyCursor(ByteView bytes, const PlyHeader& h, std::string file) : file_(std::move(file)), format_(h.format) {
    data_ = bytes.data() + h.data_offset;
    size_ = bytes.size() - h.data_offset;
    if (format_ == PlyFormat::Ascii) {
      tokens_ = split_whitespace(std::string_view(reinterpret_cast<const char*>(data_), size_));
    }
  }

  /// Next value; `where` describes the element instance for error messages.
  double next(ScalarType t, const std::string& where) {
    if (format_ == PlyFormat::Ascii) {
      if (pos_ >= tokens_.size()) truncated(where);
      const auto tok = tokens_[pos_++];
      const auto v = parse_double(tok);
      if (!v) throw InputError(file_ + ": " + where + ": '" + std::string(tok) + "' is not a number");
      return *v;
    }
    if (size_ - pos_ < t.size_bytes) truncated(where);
    const double v = load_scalar(data_ + pos_, t, format_ == PlyFormat::BinaryBig);
    pos_ += t.size_bytes;
    return v;
  }

  /// Scalars (ascii) or bytes (binary) left.
  [[nodiscard]] std::size_t remaining() const {
    return format_ == PlyFormat::Ascii ? tokens_.size() - pos_ : size_ - pos_;
  }
  [[nodiscard]] bool is_ascii() const { return format_ == PlyFormat::Ascii; }

 private:
  [[noreturn]] void truncated(const std::string& where) const {
    throw InputError(file_ + ": data ends inside " + where + " (truncated?)");
  }

  std::string file_;
  PlyFormat format_;
  const unsigned char* data_ = nullptr;
  std::size_t size_ = 0;
  std::vector<std::string_view> tokens_;
  std::size_t pos_ = 0;
};

/// Smallest size of one instance: bytes (binary) or scalars (ascii), lists counted empty.
std::size_t min_instance_size(const PlyElement& e, bool ascii) {
  std::size_t s = 0;
  for (const auto& p : e.properties) s += ascii ? 1 : (p.is_list ? p.count_type.size_bytes : p.type.size_bytes);
  return s;
}

}  // namespace

Scan read_ply(const std::filesystem::path& path) { return parse_ply(read_file_bytes(path), path.string()); }

Scan parse_ply(ByteView bytes, const std::string& file) {
  const PlyHeader h = parse_header(bytes, file);
  const PlyElement* vertex = nullptr;
  for (const auto& e : h.elements) {
    if (e.name == kVertex) vertex = &e;
  }
  if (vertex == nullptr) throw InputError(file + ": no 'vertex' element");
  std::vector<FieldSpec> fields;
  for (const auto& p : vertex->properties)
    fields.push_back({p.name, p.type, p.is_list ? 0u : 1u});  // a list has no fixed count
  const ChannelMap m = map_channels(fields, file);

  PlyCursor cur(bytes, h, file);
  std::vector<double> values;
  const std::size_t np = vertex->properties.size();
  for (const auto& e : h.elements) {
    const bool is_vertex = &e == vertex;
    if (e.properties.empty()) continue;  // instances without properties hold no data (and may be many)
    // Reject counts the data cannot hold before allocating anything for them.
    const std::size_t min_size = min_instance_size(e, cur.is_ascii());  // >= 1: there is a property
    if (e.count > cur.remaining() / min_size) {
      throw InputError(file + ": header says " + std::to_string(e.count) + " " + e.name + " elements but data holds " +
                       std::to_string(cur.remaining() / min_size) + " (truncated?)");
    }
    if (is_vertex) values.resize(e.count * np);  // np <= min_size, so at most remaining() values
    for (std::size_t i = 0; i < e.count; ++i) {
      for (std::size_t k = 0; k < e.properties.size(); ++k) {
        const auto& p = e.properties[k];
        auto where = [&] { return "element '" + e.name + "' " + std::to_string(i) + " of " + std::to_string(e.count); };
        if (p.is_list) {
          const double len = cur.next(p.count_type, where());
          // Written so that NaN fails too; ascii text may hold any number.
          if (!(len >= 0 && len <= static_cast<double>(kMaxListLength)) || std::floor(len) != len) {
            throw InputError(file + ": " + where() + ": list length " + std::to_string(len) +
                             " is not an integer in 0.." + std::to_string(kMaxListLength));
          }
          for (std::size_t j = 0; j < static_cast<std::size_t>(len); ++j) (void)cur.next(p.type, where());
        } else {
          const double v = cur.next(p.type, where());
          if (is_vertex) values[i * np + k] = v;
        }
      }
    }
  }
  if (cur.remaining() != 0) {
    throw InputError(file + ": " + std::to_string(cur.remaining()) + (cur.is_ascii() ? " values" : " bytes") +
                     " after the last element (header and data disagree)");
  }
  return assemble_scan(vertex->count, m, file, [&](std::size_t i, std::size_t k) { return values[i * np + k]; });
}

}  // namespace farlio::io
