#pragma once
// What every libFuzzer target of the readers shares: bad input must end in farlio::InputError
// (the readers' one answer to a bad file); any other exception escapes, aborts, and libFuzzer
// reports it as a crash, as it does for sanitizer errors, hangs (-timeout) and memory blow-ups
// (-rss_limit_mb). Invariants of what a reader returns are checked with FARLIO_FUZZ_CHECK.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <span>
#include <sstream>
#include <string>

#include "farlio/core/error.hpp"
#include "farlio/core/types.hpp"

namespace farlio::fuzz {

/// The name the readers give the input in their messages.
inline constexpr const char* kInputName = "fuzz-input";

/// Runs read(); an InputError is the expected answer to bad input and is swallowed.
template <class Read>
void expect_input_error_or_success(Read&& read) {
  try {
    read();
  } catch (const InputError&) {
  }
}

/// The input as bytes and as a text stream.
inline std::span<const unsigned char> bytes(const std::uint8_t* data, std::size_t size) { return {data, size}; }
inline std::istringstream text_stream(const std::uint8_t* data, std::size_t size) {
  return std::istringstream(std::string(reinterpret_cast<const char*>(data), size));
}

/// The channels of a scan a reader returned are consistent (Scan::validate's sizes).
inline bool consistent(const Scan& s) {
  const auto n = s.size();
  auto ok = [n](std::size_t m) { return m == 0 || m == n; };
  return ok(s.time_s.size()) && ok(s.intensity.size()) && ok(s.sensor_id.size());
}

}  // namespace farlio::fuzz

/// Aborts (a libFuzzer finding) when an invariant of a reader's result does not hold.
#define FARLIO_FUZZ_CHECK(cond) \
  do {                          \
    if (!(cond)) std::abort();  \
  } while (0)
