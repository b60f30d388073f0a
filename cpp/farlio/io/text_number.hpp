#pragma once
// Exact, locale-independent number text: shortest round-trip formatting and strict parsing.
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace farlio::io {

/// Shortest text that parses back to exactly `v` ("nan", "inf", "-inf" for non-finite values).
[[nodiscard]] std::string format_number(float v);
[[nodiscard]] std::string format_number(double v);

/// Nanoseconds as seconds with exactly 9 decimals, e.g. 1500000001 -> "1.500000001".
[[nodiscard]] std::string format_seconds_from_ns(std::int64_t ns);

/// The whole of `s` as a number (leading '+' allowed, "nan"/"inf" accepted); nullopt otherwise.
[[nodiscard]] std::optional<double> parse_double(std::string_view s);
[[nodiscard]] std::optional<std::int64_t> parse_int64(std::string_view s);

/// Seconds text to integer ns. Plain decimal text ("-12.000000001") converts exactly (digits
/// past the 9th decimal round half away from zero); other forms (exponents) via llround(s * 1e9).
[[nodiscard]] std::optional<std::int64_t> parse_seconds_to_ns(std::string_view s);

/// Splits on spaces, tabs and carriage returns, dropping empty tokens.
[[nodiscard]] std::vector<std::string_view> split_whitespace(std::string_view line);

/// `s` without leading and trailing spaces, tabs, carriage returns and newlines.
[[nodiscard]] std::string_view trim(std::string_view s);

}  // namespace farlio::io
