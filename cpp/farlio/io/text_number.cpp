#include "farlio/io/text_number.hpp"

#include <array>
#include <charconv>
#include <cmath>
#include <limits>

#include "farlio/core/time.hpp"

namespace farlio::io {
namespace {

constexpr int kNsDecimals = 9;
constexpr std::size_t kNumberBufferBytes = 64;

template <class T>
std::string format_float_like(T v) {
  std::array<char, kNumberBufferBytes> buf{};
  const auto res = std::to_chars(buf.data(), buf.data() + buf.size(), v);
  return std::string(buf.data(), res.ptr);
}

std::string_view strip_plus(std::string_view s) {
  if (!s.empty() && s.front() == '+') s.remove_prefix(1);
  return s;
}

bool all_digits(std::string_view s) {
  for (char c : s) {
    if (c < '0' || c > '9') return false;
  }
  return true;
}

}  // namespace

std::string format_number(float v) { return format_float_like(v); }
std::string format_number(double v) { return format_float_like(v); }

std::string format_seconds_from_ns(std::int64_t ns) {
  const bool negative = ns < 0;
  // Work with the magnitude in unsigned arithmetic so INT64_MIN is safe.
  const std::uint64_t mag =
      negative ? std::uint64_t(0) - static_cast<std::uint64_t>(ns) : static_cast<std::uint64_t>(ns);
  const std::uint64_t sec = mag / kNsPerSecond;
  std::string frac = std::to_string(mag % kNsPerSecond);
  frac.insert(0, static_cast<std::size_t>(kNsDecimals) - frac.size(), '0');
  return (negative ? "-" : "") + std::to_string(sec) + "." + frac;
}

std::optional<double> parse_double(std::string_view s) {
  s = strip_plus(s);
  if (s.empty()) return std::nullopt;
  double v = 0.0;
  const auto res = std::from_chars(s.data(), s.data() + s.size(), v);
  if (res.ec != std::errc() || res.ptr != s.data() + s.size()) return std::nullopt;
  return v;
}

std::optional<std::int64_t> parse_int64(std::string_view s) {
  s = strip_plus(s);
  if (s.empty()) return std::nullopt;
  std::int64_t v = 0;
  const auto res = std::from_chars(s.data(), s.data() + s.size(), v);
  if (res.ec != std::errc() || res.ptr != s.data() + s.size()) return std::nullopt;
  return v;
}

std::optional<std::int64_t> parse_seconds_to_ns(std::string_view s) {
  const auto as_double = parse_double(s);
  if (!as_double || !std::isfinite(*as_double)) return std::nullopt;
  std::string_view t = strip_plus(s);
  const bool negative = !t.empty() && t.front() == '-';
  if (negative) t.remove_prefix(1);
  const auto dot = t.find('.');
  const std::string_view int_part = t.substr(0, dot);
  const std::string_view frac_part = dot == std::string_view::npos ? std::string_view{} : t.substr(dot + 1);
  constexpr std::size_t kMaxIntDigits = 10;  // int64 ns reach 9223372036 s
  if (!all_digits(int_part) || !all_digits(frac_part) || int_part.size() > kMaxIntDigits ||
      (int_part.empty() && frac_part.empty())) {
    const double ns = *as_double * kNsPerS;
    if (std::fabs(ns) >= static_cast<double>(std::numeric_limits<std::int64_t>::max())) return std::nullopt;
    return static_cast<std::int64_t>(std::llround(ns));
  }
  std::int64_t sec = 0;
  for (char c : int_part) sec = sec * 10 + (c - '0');
  std::int64_t frac = 0;
  for (std::size_t k = 0; k < static_cast<std::size_t>(kNsDecimals); ++k) {
    frac = frac * 10 + (k < frac_part.size() ? frac_part[k] - '0' : 0);
  }
  constexpr char kRoundUpDigit = '5';
  if (frac_part.size() > static_cast<std::size_t>(kNsDecimals) && frac_part[kNsDecimals] >= kRoundUpDigit) ++frac;
  constexpr std::int64_t kMaxNs = std::numeric_limits<std::int64_t>::max();
  if (sec > (kMaxNs - frac) / kNsPerSecond) return std::nullopt;  // out of int64 range
  const std::int64_t ns = sec * kNsPerSecond + frac;
  return negative ? -ns : ns;
}

std::vector<std::string_view> split_whitespace(std::string_view line) {
  std::vector<std::string_view> out;
  std::size_t i = 0;
  auto is_space = [](char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n'; };
  while (i < line.size()) {
    while (i < line.size() && is_space(line[i])) ++i;
    const std::size_t start = i;
    while (i < line.size() && !is_space(line[i])) ++i;
    if (i > start) out.push_back(line.substr(start, i - start));
  }
  return out;
}

std::string_view trim(std::string_view s) {
  constexpr std::string_view kSpace = " \t\r\n";
  const auto b = s.find_first_not_of(kSpace);
  if (b == std::string_view::npos) return {};
  const auto e = s.find_last_not_of(kSpace);
  return s.substr(b, e - b + 1);
}

}  // namespace farlio::io
