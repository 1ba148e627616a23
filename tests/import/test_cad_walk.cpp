// What a reader's child sends back (cad_transfer.h): the document walked into parts and instances,
// each part's shape apart when no part shares anything with another, and instances placed as the
// stored document placed them; the caller makes only the shapes its cache does not hold.
#include "brep_part_cache.h"
#include "cad_transfer.h"
#include "cad_xcaf.h"
#include "../test_temp.h"

#include <BRepBuilderAPI_MakeFace.hxx>
#include <BRepPrimAPI_MakeBox.hxx>
#include <BRep_Builder.hxx>
#include <BinTools.hxx>
#include <Geom_Plane.hxx>
#include <TDataStd_Name.hxx>
#include <TopExp.hxx>
#include <TopExp_Explorer.hxx>
#include <TopLoc_Datum3D.hxx>
#include <TopTools_IndexedMapOfShape.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Compound.hxx>
#include <XCAFApp_Application.hxx>
#include <XCAFDoc_DocumentTool.hxx>
#include <XCAFDoc_ShapeTool.hxx>
#include <gp_Ax1.hxx>
#include <gp_Ax2.hxx>

#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

namespace cadclash {
namespace {

using detail::WalkedDocument;

// A document the isolated reader could make (its binary format known to the application).
struct Doc {
  Handle(TDocStd_Document) doc = detail::new_xcaf_document();
  Handle(XCAFDoc_ShapeTool) tool = XCAFDoc_DocumentTool::ShapeTool(doc->Main());
  ~Doc() {
    if (doc->IsOpened()) XCAFApp_Application::GetApplication()->Close(doc);
  }
  TDF_Label add(const TopoDS_Shape& shape, const char* name) {
    const TDF_Label l = tool->AddShape(shape, Standard_False);
    TDataStd_Name::Set(l, TCollection_ExtendedString(name));
    return l;
  }
};

// The document stored in OCCT's binary format and read back, as the isolated reader once sent it.
Handle(TDocStd_Document) stored_and_read(const Handle(TDocStd_Document)& doc) {
  const Handle(XCAFApp_Application) app = XCAFApp_Application::GetApplication();
  std::ostringstream out;
  EXPECT_EQ(app->SaveAs(doc, out), PCDM_SS_OK);
  std::istringstream in(out.str());
  Handle(TDocStd_Document) back;
  EXPECT_EQ(app->Open(in, back), PCDM_RS_OK);
  return back;
}

gp_Trsf turn(double angle, const gp_Vec& shift) {
  gp_Trsf t;
  t.SetRotation(gp_Ax1(gp_Pnt(1, 2, 3), gp_Dir(1, 1, 1)), angle);
  gp_Trsf s;
  s.SetTranslation(shift);
  return s * t;
}

bool same_pose(const Pose& a, const Pose& b) { return std::memcmp(a.matrix().data(), b.matrix().data(), 16 * sizeof(double)) == 0; }

// Components placed by a turn, a reflection, a chain of two datums (one squared) and, in a nested
// assembly, one datum at two levels: a walk in the child with its locations as stored places every
// instance bit for bit as the walk of the stored document did.
TEST(CadWalk, AChildPlacesInstancesAsTheStoredDocumentDid) {
  Doc d;
  const TDF_Label box = d.add(BRepPrimAPI_MakeBox(1.0, 2.0, 3.0).Shape(), "box");
  const TDF_Label top = d.tool->NewShape();
  TDataStd_Name::Set(top, TCollection_ExtendedString("top"));
  const TDF_Label sub = d.tool->NewShape();
  TDataStd_Name::Set(sub, TCollection_ExtendedString("sub"));
  gp_Trsf mirror;
  mirror.SetMirror(gp_Ax2(gp_Pnt(0.3, -0.1, 0.7), gp_Dir(1.0, 0.2, -0.4)));
  const Handle(TopLoc_Datum3D) shift = new TopLoc_Datum3D(turn(0.3, gp_Vec(0.1, 0.2, 0.3)));
  const Handle(TopLoc_Datum3D) twist = new TopLoc_Datum3D(turn(-1.1, gp_Vec(-7.25, 3.5, 0.125)));
  d.tool->AddComponent(top, box, TopLoc_Location(turn(0.7, gp_Vec(0.1, -0.2, 5.3))));
  d.tool->AddComponent(top, box, TopLoc_Location(mirror));
  d.tool->AddComponent(top, box, TopLoc_Location(shift) * TopLoc_Location(twist).Powered(2));
  d.tool->AddComponent(sub, box, TopLoc_Location(shift));
  d.tool->AddComponent(sub, box, TopLoc_Location(mirror) * TopLoc_Location(twist));
  d.tool->AddComponent(top, sub, TopLoc_Location(shift));
  d.tool->UpdateAssemblies();

  const Handle(TDocStd_Document) back = stored_and_read(d.doc);
  const WalkedDocument child = detail::walk_xcaf_document(d.doc, "placed.step", SourceKind::StepFace, {}, {}, true);
  const WalkedDocument parent = detail::walk_xcaf_document(back, "placed.step", SourceKind::StepFace, {}, {}, false);
  const WalkedDocument here = detail::walk_xcaf_document(d.doc, "placed.step", SourceKind::StepFace, {}, {}, false);
  XCAFApp_Application::GetApplication()->Close(back);
  ASSERT_EQ(child.instances.size(), 5u);
  ASSERT_EQ(parent.instances.size(), child.instances.size());
  std::size_t moved = 0;  // instances a walk of the unstored locations places otherwise
  for (std::size_t k = 0; k < child.instances.size(); ++k) {
    SCOPED_TRACE(child.instances[k].path);
    EXPECT_EQ(child.instances[k].path, parent.instances[k].path);
    EXPECT_TRUE(same_pose(child.instances[k].pose, parent.instances[k].pose));
    EXPECT_EQ(child.chains[k], parent.chains[k]);
    if (!same_pose(here.instances[k].pose, parent.instances[k].pose)) ++moved;
  }
  EXPECT_GT(moved, 0u);  // the reflection: what storing does to a location is not nothing
  EXPECT_EQ(child.diagnostics.size(), parent.diagnostics.size());
}

// Two free shapes walked in a child, packed and unpacked; `share` says whether they share anything.
WalkedDocument sent_back(const TopoDS_Shape& a, const TopoDS_Shape& b) {
  detail::Transfer t;
  {
    t.doc = detail::new_xcaf_document();
    const Handle(XCAFDoc_ShapeTool) tool = XCAFDoc_DocumentTool::ShapeTool(t.doc->Main());
    TDataStd_Name::Set(tool->AddShape(a, Standard_False), TCollection_ExtendedString("a"));
    TDataStd_Name::Set(tool->AddShape(b, Standard_False), TCollection_ExtendedString("b"));
  }
  detail::walk_transfer(t, "sent.step", true);
  const std::string bytes = detail::pack_transfer(t);
  EXPECT_EQ(detail::pack_transfer(t, 4), bytes);  // the parts written on threads: the same bytes
  detail::Transfer back;
  std::string why;
  EXPECT_TRUE(detail::unpack_transfer(bytes, back, why)) << why;
  EXPECT_TRUE(back.walked.has_value());
  return back.walked ? std::move(*back.walked) : WalkedDocument{};
}

std::size_t face_count(const TopoDS_Shape& s) {
  TopTools_IndexedMapOfShape faces;
  TopExp::MapShapes(s, TopAbs_FACE, faces);
  return static_cast<std::size_t>(faces.Extent());
}

TEST(CadWalk, PartsThatShareNothingAreSentApartAsTheirKeysWriteThem) {
  const TopoDS_Shape a = BRepPrimAPI_MakeBox(1.0, 1.0, 1.0).Shape();
  const TopoDS_Shape b = BRepPrimAPI_MakeBox(gp_Pnt(5, 0, 0), 2.0, 1.0, 1.0).Shape();
  const WalkedDocument w = sent_back(a, b);
  ASSERT_EQ(w.parts.size(), 2u);
  for (std::size_t p = 0; p < 2; ++p) {
    EXPECT_TRUE(w.parts[p].shape.IsNull()) << "made before it is asked for";
    ASSERT_FALSE(w.parts[p].packed.empty());
    std::ostringstream written;  // what a part's cache key hashes
    BinTools::Write(p == 0 ? a : b, written, Standard_False, Standard_False, BinTools_FormatVersion_CURRENT);
    EXPECT_EQ(w.parts[p].packed, written.str());
    EXPECT_EQ(w.parts[p].tags.size(), 6u);
  }
  EXPECT_EQ(w.instances.size(), 2u);
}

TEST(CadWalk, PartsThatShareAFaceOrASurfaceAreSentTogetherAndStillShare) {
  const TopoDS_Shape box = BRepPrimAPI_MakeBox(1.0, 1.0, 1.0).Shape();
  TopoDS_Compound one_face;
  BRep_Builder().MakeCompound(one_face);
  BRep_Builder().Add(one_face, TopExp_Explorer(box, TopAbs_FACE).Current());
  const WalkedDocument w = sent_back(box, one_face);
  ASSERT_EQ(w.parts.size(), 2u);
  for (const detail::WalkedPart& p : w.parts) {
    EXPECT_TRUE(p.packed.empty());
    ASSERT_FALSE(p.shape.IsNull());
  }
  EXPECT_EQ(face_count(w.parts[0].shape), 6u);
  ASSERT_EQ(face_count(w.parts[1].shape), 1u);
  const TopoDS_Shape shared = TopExp_Explorer(w.parts[1].shape, TopAbs_FACE).Current();
  bool found = false;
  for (TopExp_Explorer f(w.parts[0].shape, TopAbs_FACE); f.More(); f.Next()) found = found || f.Current().TShape() == shared.TShape();
  EXPECT_TRUE(found) << "the face the parts shared is two faces now";

  // Two faces of their own on one plane: healing one could change the other's surface.
  const Handle(Geom_Plane) plane = new Geom_Plane(gp_Pnt(0, 0, 0), gp_Dir(0, 0, 1));
  const WalkedDocument on_one_plane = sent_back(BRepBuilderAPI_MakeFace(plane, 0.0, 1.0, 0.0, 1.0, 1e-7).Face(),
                                                BRepBuilderAPI_MakeFace(plane, 2.0, 3.0, 0.0, 1.0, 1e-7).Face());
  ASSERT_EQ(on_one_plane.parts.size(), 2u);
  for (const detail::WalkedPart& p : on_one_plane.parts) EXPECT_TRUE(p.packed.empty());
}

// Parts the cache holds are not made from their bytes; the others are, and bytes OCCT cannot read
// leave their part without faces and say so.
TEST(CadWalk, OnlyPartsTheCacheDoesNotHoldAreMadeFromTheirBytes) {
  ImportOptions options;
  options.lazy = true;
  options.cache_dir = testing::scratch_dir() + "/walk_cache";
  std::filesystem::remove_all(options.cache_dir);
  const std::vector<TopoDS_Shape> boxes{BRepPrimAPI_MakeBox(1.0, 1.0, 1.0).Shape(),
                                        BRepPrimAPI_MakeBox(gp_Pnt(5, 0, 0), 2.0, 1.0, 1.0).Shape(),
                                        BRepPrimAPI_MakeBox(gp_Pnt(9, 0, 0), 1.0, 3.0, 1.0).Shape()};
  std::vector<std::string> bytes;
  for (const TopoDS_Shape& s : boxes) {
    std::ostringstream out;
    BinTools::Write(s, out, Standard_False, Standard_False, BinTools_FormatVersion_CURRENT);
    bytes.push_back(out.str());
  }
  struct Run {
    Model model;
    std::vector<Diagnostic> diagnostics;
    bool complete = true;
    std::size_t cached = 0;
    std::vector<TopoDS_Shape> shapes;
  };
  auto run = [&](const std::vector<std::string>& packed) {
    Run r;
    r.shapes.resize(packed.size());
    std::vector<BrepPartInput> parts(packed.size());
    for (std::size_t k = 0; k < parts.size(); ++k) {
      parts[k].shape = &r.shapes[k];
      parts[k].name = "box" + std::to_string(k);
      parts[k].source_file = "boxes.step";
      parts[k].kind = SourceKind::StepFace;
    }
    const detail::PackedShapes shapes{packed, r.shapes};
    detail::add_brep_parts_cached(r.model, parts, options, r.diagnostics, r.complete, nullptr, &r.cached, nullptr, &shapes);
    return r;
  };
  const Run cold = run(bytes);
  EXPECT_EQ(cold.cached, 0u);
  for (const TopoDS_Shape& s : cold.shapes) EXPECT_FALSE(s.IsNull());
  ASSERT_EQ(cold.model.surfaces.size(), 18u);

  std::vector<std::string> edited = bytes;
  edited[1] = bytes[2];  // another box in the middle
  const Run again = run(edited);
  EXPECT_EQ(again.cached, 2u);
  EXPECT_TRUE(again.shapes[0].IsNull());
  EXPECT_FALSE(again.shapes[1].IsNull());
  EXPECT_TRUE(again.shapes[2].IsNull());
  ASSERT_EQ(again.model.surfaces.size(), 18u);
  EXPECT_TRUE(again.complete);
  for (std::size_t s = 0; s < 18; ++s)
    EXPECT_EQ(again.model.surfaces[s].aabb.max(), (s / 6 == 1 ? cold.model.surfaces[12 + s % 6] : cold.model.surfaces[s]).aabb.max());

  std::vector<std::string> damaged = bytes;
  damaged[0] = "not a shape";
  std::filesystem::remove_all(options.cache_dir);
  const Run broken = run(damaged);
  EXPECT_FALSE(broken.complete);
  ASSERT_EQ(broken.model.parts.size(), 3u);
  EXPECT_EQ(broken.model.parts[0].surface_count, 0u);
  EXPECT_EQ(broken.model.parts[1].surface_count, 6u);
  bool said = false;
  for (const Diagnostic& d : broken.diagnostics)
    said = said || (d.severity == Severity::Error &&
                    d.message.rfind("part 'box0' could not be made again from what the isolated reader sent", 0) == 0);
  EXPECT_TRUE(said);
}

}  // namespace
}  // namespace cadclash
