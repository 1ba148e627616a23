// Parts made from OCCT shapes built in a test ("shape0", "shape1", ... from "built-in").
#pragma once

#include "cadclash/tessellate.h"

#include <TopoDS_Shape.hxx>

#include <string>
#include <vector>

namespace cadclash::testing {

struct Built {
  Model model;
  std::vector<Diagnostic> diagnostics;
  bool complete = true;
};

inline Built build_parts(const std::vector<TopoDS_Shape>& shapes, const TessellationOptions& options, bool lazy) {
  Built b;
  std::vector<BrepPartInput> inputs;
  for (std::size_t i = 0; i < shapes.size(); ++i) {
    BrepPartInput in;
    in.shape = &shapes[i];
    in.name = "shape" + std::to_string(i);
    in.source_file = "built-in";
    inputs.push_back(std::move(in));
  }
  add_brep_parts(b.model, inputs, options, lazy, b.diagnostics, b.complete);
  return b;
}

}  // namespace cadclash::testing
