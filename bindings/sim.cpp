#include "bindings.hpp"

namespace farlio::python {
void bind_sim(nanobind::module_& /*m*/) {}  // filled in when the sim module lands
}  // namespace farlio::python
