#include "bindings.hpp"

namespace farlio::python {
void bind_io(nanobind::module_& /*m*/) {}  // filled in when the io module lands
}  // namespace farlio::python
