#include "farlio/io/size_limits.hpp"

#include "farlio/core/error.hpp"

namespace farlio::io {

std::optional<std::size_t> checked_mul(std::size_t a, std::size_t b) {
  std::size_t r = 0;
  if (__builtin_mul_overflow(a, b, &r)) return std::nullopt;
  return r;
}

std::optional<std::size_t> checked_add(std::size_t a, std::size_t b) {
  std::size_t r = 0;
  if (__builtin_add_overflow(a, b, &r)) return std::nullopt;
  return r;
}

void require_within_limit(std::size_t value, std::size_t limit, const std::string& file, const std::string& what) {
  if (value > limit) throw InputError(file + ": " + what + " is over the limit of " + std::to_string(limit));
}

}  // namespace farlio::io
