#pragma once
// Thread-safety of the bound classes (docs/hardening.md): the methods that release the GIL work on
// state no other call may touch meanwhile, so Odometry, ScanPipeline and MapExport hold a mutex
// of their own in every method; it is taken after the GIL is released (a thread waiting for it
// never blocks Python) and nothing called under it needs the GIL. OnlineOdometry is thread-safe
// itself. The other classes keep the GIL in every method.
#include <mutex>

namespace farlio::python {

/// Calls f(object) holding the object's mutex.
template <typename T, typename F>
auto locked(T& o, F&& f) {
  std::lock_guard lock(o.mutex);
  return f(o);
}

}  // namespace farlio::python
