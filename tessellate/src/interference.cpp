// The Boolean common of two placed B-rep parts: volume, centroid, depth (cadclash/interference.h).
#include "cadclash/interference.h"

#include "cadclash/tessellate.h"

#include <BRepAlgoAPI_Common.hxx>
#include <BRepBndLib.hxx>
#include <BRepBuilderAPI_MakeSolid.hxx>
#include <BRepBuilderAPI_Sewing.hxx>
#include <BRepGProp.hxx>
#include <BRepLib.hxx>
#include <BRep_Builder.hxx>
#include <BRep_Tool.hxx>
#include <Bnd_OBB.hxx>
#include <GProp_GProps.hxx>
#include <Standard_Failure.hxx>
#include <TopExp_Explorer.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Compound.hxx>
#include <TopoDS_Shell.hxx>
#include <TopoDS_Solid.hxx>
#include <gp_Trsf.hxx>

#include <algorithm>
#include <optional>

namespace cadclash {
namespace {

// The part's faces sewn into closed shells, each made a solid; nullopt (and `note`) otherwise.
std::optional<TopoDS_Shape> part_solid(const Model& m, PartId p, std::string& note) {
  const Part& part = m.parts[p];
  const auto* brep = dynamic_cast<const BrepSource*>(part.source.get());
  if (!brep) {
    note = "part " + part.name + " is not a B-rep part (a mesh): no solid to intersect";
    return std::nullopt;
  }
  double tolerance = 1e-6;
  BRepBuilderAPI_Sewing sewing(tolerance);
  for (std::uint32_t k = 0; k < brep->face_count(); ++k) {
    const TopoDS_Face& f = brep->face(k);
    tolerance = std::max(tolerance, BRep_Tool::MaxTolerance(f, TopAbs_VERTEX));
    sewing.Add(f);
  }
  sewing.SetTolerance(tolerance);
  sewing.Perform();
  if (sewing.NbFreeEdges() > 0) {
    note = "part " + part.name + " is not a closed solid (" + std::to_string(sewing.NbFreeEdges()) + " free edges)";
    return std::nullopt;
  }
  TopoDS_Compound solids;
  BRep_Builder builder;
  builder.MakeCompound(solids);
  int shells = 0;
  for (TopExp_Explorer e(sewing.SewedShape(), TopAbs_SHELL); e.More(); e.Next(), ++shells) {
    BRepBuilderAPI_MakeSolid make(TopoDS::Shell(e.Current()));
    if (!make.IsDone()) break;
    TopoDS_Solid solid = make.Solid();
    BRepLib::OrientClosedSolid(solid);  // outward normals, whatever the faces' order
    builder.Add(solids, solid);
  }
  if (shells == 0) {
    note = "part " + part.name + " is not a closed solid (its faces form no shell)";
    return std::nullopt;
  }
  return TopoDS_Shape(solids);
}

TopoDS_Shape placed(const TopoDS_Shape& s, const Pose& pose) {
  gp_Trsf t;
  const auto& r = pose.matrix();
  t.SetValues(r(0, 0), r(0, 1), r(0, 2), r(0, 3), r(1, 0), r(1, 1), r(1, 2), r(1, 3), r(2, 0), r(2, 1), r(2, 2), r(2, 3));
  return s.Moved(TopLoc_Location(t));
}

}  // namespace

InterferenceResult measure_interference(const Model& model, InstanceId a, InstanceId b) {
  InterferenceResult out;
  try {
    const std::optional<TopoDS_Shape> sa = part_solid(model, model.instances[a].part, out.note);
    if (!sa) return out;
    const std::optional<TopoDS_Shape> sb = part_solid(model, model.instances[b].part, out.note);
    if (!sb) return out;
    BRepAlgoAPI_Common common(placed(*sa, model.instances[a].pose), placed(*sb, model.instances[b].pose));
    if (!common.IsDone() || common.HasErrors()) {
      out.note = "OCCT's Boolean common of the two solids failed";
      return out;
    }
    GProp_GProps props;
    BRepGProp::VolumeProperties(common.Shape(), props);
    out.measured = true;
    out.volume = std::max(0.0, props.Mass());
    if (out.volume > 0.0) {
      const gp_Pnt c = props.CentreOfMass();
      out.centroid = Vec3(c.X(), c.Y(), c.Z());
      Bnd_OBB box;
      BRepBndLib::AddOBB(common.Shape(), box, /*theIsTriangulationUsed=*/false, /*theIsOptimal=*/true);
      out.depth = 2.0 * std::min({box.XHSize(), box.YHSize(), box.ZHSize()});
    }
  } catch (const Standard_Failure& e) {
    out = {};
    out.note = std::string("OCCT failed: ") + e.GetMessageString();
  }
  return out;
}

}  // namespace cadclash
