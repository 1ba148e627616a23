// What the Python objects share: the imported model, the lock that serialises writers of it, and
// the load settings later queries default to.
#pragma once

#include "cadclash/import.h"

#include <pybind11/pybind11.h>

#include <memory>
#include <mutex>

namespace cadclash::py {

namespace pyb = pybind11;

// One loaded model. Scenes and one-off queries write into `model` (lazy tessellation) and scenes
// keep their own poses, so every call that may write, or read what a writer changes, holds `mutex`
// with the GIL released. A surface that has triangles when a query starts keeps them unchanged (a
// query only gives back triangles it made itself, under a memory budget, before it returns), so
// NumPy views of them, made only while no query runs, stay valid.
struct ModelState {
  Model model;
  std::mutex mutex;
  bool loaded = false;
  // How it was loaded, for the report's settings: the preset's name (empty: none), the
  // tessellation in effect (the preset's when one was given) and lazy.
  std::string preset;
  TessellationOptions tessellation;
  bool lazy = false;
};

// The Python-visible model core (subclassed in Python as cadclash.Model).
struct ModelCore {
  std::shared_ptr<ModelState> state = std::make_shared<ModelState>();
};

// Holds `state->mutex` with the GIL released. Declared in this order so the lock is dropped before
// the GIL is taken back: a thread waiting for the lock never holds the GIL.
class ModelLock {
 public:
  explicit ModelLock(ModelState& s) : lock_(s.mutex) {}

 private:
  pyb::gil_scoped_release release_;
  std::lock_guard<std::mutex> lock_;
};

void bind_model(pyb::module_& m);
void bind_scene(pyb::module_& m);
void bind_report(pyb::module_& m);

}  // namespace cadclash::py
