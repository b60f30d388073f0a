#include "bindings.hpp"

namespace farlio::python {
void bind_eval(nanobind::module_& /*m*/) {}  // filled in when the eval module lands
}  // namespace farlio::python
