#include "farlio/io/pcd_header.hpp"

#include <optional>
#include <sstream>
#include <string_view>

#include "farlio/core/error.hpp"
#include "farlio/io/size_limits.hpp"
#include "farlio/io/text_number.hpp"

namespace farlio::io {
namespace {

constexpr std::size_t kViewpointValues = 7;  // tx ty tz qw qx qy qz

std::optional<ScalarType> pcd_type(std::string_view letter, std::size_t size) {
  ScalarType t;
  if (letter == "F")
    t.kind = ScalarKind::Float;
  else if (letter == "I")
    t.kind = ScalarKind::Int;
  else if (letter == "U")
    t.kind = ScalarKind::Uint;
  else
    return std::nullopt;
  t.size_bytes = size;
  if (!t.is_valid()) return std::nullopt;
  return t;
}

char pcd_letter(ScalarKind kind) {
  switch (kind) {
    case ScalarKind::Float: return 'F';
    case ScalarKind::Int: return 'I';
    case ScalarKind::Uint: return 'U';
  }
  return 'F';
}

class HeaderParser {
 public:
  HeaderParser(ByteView bytes, std::string file) : bytes_(bytes), file_(std::move(file)) {}

  PcdHeader parse() {
    std::size_t pos = 0;
    for (;;) {
      if (pos >= bytes_.size()) fail("header ends without a DATA line (truncated or not a PCD file?)");
      std::size_t nl = pos;
      while (nl < bytes_.size() && bytes_[nl] != '\n') ++nl;
      const std::string_view line(reinterpret_cast<const char*>(bytes_.data()) + pos, nl - pos);
      ++line_;
      pos = nl + 1;
      const auto tokens = split_whitespace(line);
      if (tokens.empty() || tokens.front().front() == '#') continue;
      if (handle(tokens)) {
        h_.data_offset = std::min(pos, bytes_.size());
        h_.header_lines = line_;
        break;
      }
    }
    finish();
    return h_;
  }

 private:
  [[noreturn]] void fail(const std::string& what) const { throw InputError(file_ + ": " + what); }

  std::size_t to_size(std::string_view key, std::string_view tok) const {
    const auto v = parse_int64(tok);
    if (!v || *v < 0) fail(std::string(key) + " value '" + std::string(tok) + "' is not a non-negative integer");
    return static_cast<std::size_t>(*v);
  }

  std::vector<std::size_t> sizes(std::string_view key, const std::vector<std::string_view>& tokens) const {
    std::vector<std::size_t> out;
    for (std::size_t k = 1; k < tokens.size(); ++k) out.push_back(to_size(key, tokens[k]));
    return out;
  }

  std::size_t single(std::string_view key, const std::vector<std::string_view>& tokens) const {
    if (tokens.size() != 2) fail(std::string(key) + " needs exactly one value (line " + std::to_string(line_) + ")");
    return to_size(key, tokens[1]);
  }

  /// Returns true on the DATA line, which ends the header.
  bool handle(const std::vector<std::string_view>& tokens) {
    const std::string key(tokens.front());
    if (key == "VERSION") {
      version_ = true;
    } else if (key == "FIELDS") {
      for (std::size_t k = 1; k < tokens.size(); ++k) names_.emplace_back(tokens[k]);
      fields_seen_ = true;
    } else if (key == "SIZE") {
      size_ = sizes(key, tokens);
    } else if (key == "TYPE") {
      for (std::size_t k = 1; k < tokens.size(); ++k) types_.emplace_back(tokens[k]);
    } else if (key == "COUNT") {
      count_ = sizes(key, tokens);
    } else if (key == "WIDTH") {
      width_ = single(key, tokens);
    } else if (key == "HEIGHT") {
      h_.height = single(key, tokens);
    } else if (key == "VIEWPOINT") {
      if (tokens.size() != kViewpointValues + 1) fail("VIEWPOINT needs 7 values");
      for (std::size_t k = 1; k < tokens.size(); ++k) {
        if (!parse_double(tokens[k])) fail("VIEWPOINT value '" + std::string(tokens[k]) + "' is not a number");
      }
    } else if (key == "POINTS") {
      points_ = single(key, tokens);
    } else if (key == "DATA") {
      if (tokens.size() != 2) fail("DATA needs exactly one value");
      const auto enc = parse_pcd_encoding(tokens[1]);
      if (!enc)
        fail("unknown DATA encoding '" + std::string(tokens[1]) + "' (expected ascii, binary or binary_compressed)");
      h_.encoding = *enc;
      return true;
    } else {
      fail("unknown header key '" + key + "' on line " + std::to_string(line_));
    }
    return false;
  }

  void finish() {
    if (!fields_seen_ || names_.empty()) fail("header has no FIELDS line");
    if (size_.empty()) fail("header has no SIZE line");
    if (types_.empty()) fail("header has no TYPE line");
    if (!width_) fail("header has no WIDTH line");
    (void)version_;  // VERSION is optional: PCL itself accepts files without it
    const std::size_t nf = names_.size();
    if (count_.empty()) count_.assign(nf, 1);
    if (size_.size() != nf || types_.size() != nf || count_.size() != nf) {
      fail("FIELDS lists " + std::to_string(nf) + " fields but SIZE has " + std::to_string(size_.size()) + ", TYPE " +
           std::to_string(types_.size()) + " and COUNT " + std::to_string(count_.size()) + " values");
    }
    for (std::size_t k = 0; k < nf; ++k) {
      const auto type = pcd_type(types_[k], size_[k]);
      if (!type) {
        fail("field '" + names_[k] + "' has unsupported TYPE " + types_[k] + " with SIZE " + std::to_string(size_[k]));
      }
      if (count_[k] == 0) fail("field '" + names_[k] + "' has COUNT 0");
      require_within_limit(count_[k], kMaxFieldCount, file_,
                           "COUNT " + std::to_string(count_[k]) + " of field '" + names_[k] + "'");
      h_.fields.push_back({names_[k], *type, count_[k]});
      // SIZE <= 8 and COUNT <= kMaxFieldCount: the product fits, the sum is checked.
      const auto record = checked_add(h_.record_bytes, type->size_bytes * count_[k]);
      if (!record) fail("the record size (sum of SIZE * COUNT over the fields) overflows");
      h_.record_bytes = *record;
    }
    h_.width = *width_;
    require_within_limit(h_.width, kMaxCloudPoints, file_, "WIDTH " + std::to_string(h_.width));
    require_within_limit(h_.height, kMaxCloudPoints, file_, "HEIGHT " + std::to_string(h_.height));
    const auto wh = checked_mul(h_.width, h_.height);
    if (!wh) fail("WIDTH * HEIGHT overflows");
    require_within_limit(*wh, kMaxCloudPoints, file_, "WIDTH * HEIGHT = " + std::to_string(*wh) + " points");
    if (points_ && *points_ != *wh) {
      fail("POINTS " + std::to_string(*points_) + " differs from WIDTH * HEIGHT = " + std::to_string(*wh));
    }
    h_.points = *wh;
    const auto data = checked_mul(h_.points, h_.record_bytes);
    if (!data) {
      fail(std::to_string(h_.points) + " points of " + std::to_string(h_.record_bytes) +
           " bytes each overflow the size of the data");
    }
    h_.data_bytes = *data;
  }

  ByteView bytes_;
  std::string file_;
  std::size_t line_ = 0;
  PcdHeader h_;
  bool version_ = false;
  bool fields_seen_ = false;
  std::vector<std::string> names_;
  std::vector<std::size_t> size_;
  std::vector<std::string> types_;
  std::vector<std::size_t> count_;
  std::optional<std::size_t> width_;
  std::optional<std::size_t> points_;
};

}  // namespace

PcdHeader parse_pcd_header(ByteView bytes, const std::string& file) { return HeaderParser(bytes, file).parse(); }

std::string format_pcd_header(const std::vector<FieldSpec>& fields, std::size_t points, PcdEncoding encoding) {
  std::ostringstream h;
  h << "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\nFIELDS";
  for (const auto& f : fields) h << ' ' << f.name;
  h << "\nSIZE";
  for (const auto& f : fields) h << ' ' << f.type.size_bytes;
  h << "\nTYPE";
  for (const auto& f : fields) h << ' ' << pcd_letter(f.type.kind);
  h << "\nCOUNT";
  for (const auto& f : fields) h << ' ' << f.count;
  h << "\nWIDTH " << points << "\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS " << points << "\nDATA "
    << to_string(encoding) << '\n';
  return h.str();
}

}  // namespace farlio::io
