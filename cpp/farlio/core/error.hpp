#pragma once
// Exceptions thrown by farlio. Every message names the file, message or field at fault,
// so a user can find what is wrong without a debugger.
#include <stdexcept>
#include <string>

namespace farlio {

/// Bad input data: a missing, truncated or malformed file, an inconsistent scan, a bad field.
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A limit of a preallocated structure was reached (e.g. a full hash table).
class CapacityError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A CUDA runtime call failed; the message names the call, its file:line and the CUDA error.
class DeviceError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace farlio
