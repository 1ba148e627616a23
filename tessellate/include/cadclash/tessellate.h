// cadclash/tessellate.h — B-rep faces to tagged triangle surfaces (OCCT BRepMesh), and raw mesh
// repair / segmentation (CGAL). The one public header of cadclash::tessellate.
#pragma once

#include "cadclash/collide.h"

namespace cadclash {

// How finely B-rep faces are triangulated.
struct TessellationOptions {
  double linear_deflection = 0.1;   // chord error bound; millimetres, or a fraction of the part size if relative
  bool relative = false;            // linear_deflection is relative to each part's bounding-box diagonal
  double angular_deflection = 0.5;  // radians between adjacent normals along a curve
  bool parallel = true;             // let BRepMesh mesh faces of one part in parallel
};

}  // namespace cadclash
