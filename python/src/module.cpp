// The compiled core of the `cadclash` Python package. The public API is the pure-Python package
// (python/cadclash/); names here are its building blocks.
#include "state.h"

PYBIND11_MODULE(_cadclash, m) {
  m.doc() = "Compiled core of the cadclash package; use `import cadclash`.";
  cadclash::py::bind_model(m);
  cadclash::py::bind_scene(m);
  cadclash::py::bind_report(m);
}
