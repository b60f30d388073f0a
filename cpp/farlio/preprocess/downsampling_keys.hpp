#pragma once
// The CPU's batch of downsampling_key (preprocess_point.hpp): the same keys, computed four points
// at a time with SSE2 (x86-64's baseline) where the host has it, point by point otherwise. The
// keys were three quarters of the preprocessing's loop, most of it the three floors per point
// (docs/performance.md). CUDA runs downsampling_key itself, one thread a point;
// tests/cpp/test_shared_bodies.cpp checks that both give the same keys, bit for bit.
#include <cstddef>
#include <cstdint>

#include "farlio/core/types.hpp"
#include "farlio/preprocess/preprocess_point.hpp"

namespace farlio::preprocess {

/// keys[i] = downsampling_key(points[i], pp) for i in [0, n).
void downsampling_keys(const Vec3f* points, std::size_t n, const PreprocessParams& pp, std::uint64_t* keys);

/// keys[i] = map::kEmptyKey for each point that finite_point rejects (`times`: the points' times,
/// or null for a scan without them); returns how many. Run on the block downsampling_keys has
/// just read, it screens the scan without another pass over it from memory.
std::size_t drop_non_finite(const Vec3f* points, const float* times, std::size_t n, std::uint64_t* keys);

}  // namespace farlio::preprocess
