// IGES and BREP import on the real sample files: face counts against OCCT's own reading.
#include "cadclash/import.h"

#include <BRepTools.hxx>
#include <BRep_Builder.hxx>
#include <IGESControl_Reader.hxx>
#include <TopExp.hxx>
#include <TopTools_IndexedMapOfShape.hxx>
#include <TopoDS_Shape.hxx>

#include <gtest/gtest.h>

#include <filesystem>

namespace cadclash {
namespace {

const std::string kExternal = std::string(CADCLASH_DATA_DIR) + "/external/";

int face_count(const TopoDS_Shape& shape) {
  TopTools_IndexedMapOfShape faces;
  TopExp::MapShapes(shape, TopAbs_FACE, faces);
  return faces.Extent();
}

TEST(CadIges, BearingFacesMatchOcctWithDirectoryEntryIds) {
  const std::string path = kExternal + "bearing.iges";
  if (!std::filesystem::exists(path)) GTEST_SKIP() << path << " missing";
  IGESControl_Reader occt;
  ASSERT_EQ(occt.ReadFile(path.c_str()), IFSelect_RetDone);
  occt.TransferRoots();
  const int expected = face_count(occt.OneShape());
  const ImportResult r = import_file(path);
  EXPECT_EQ(r.model.surfaces.size(), static_cast<std::size_t>(expected));
  EXPECT_EQ(r.model.instances.size(), 1u);
  for (const Surface& s : r.model.surfaces) {
    EXPECT_EQ(s.provenance.kind, SourceKind::IgesFace);
    EXPECT_GT(s.provenance.step_id, 0);
    EXPECT_EQ(s.provenance.step_id % 2, 1) << "IGES directory entry numbers are odd";
    EXPECT_TRUE(s.has_triangles);
  }
}

class CadBrep : public ::testing::TestWithParam<const char*> {};

TEST_P(CadBrep, OnePartNamedAfterTheFileWithOcctsFaces) {
  const std::string path = kExternal + GetParam();
  if (!std::filesystem::exists(path)) GTEST_SKIP() << path << " missing";
  TopoDS_Shape shape;
  BRep_Builder builder;
  ASSERT_TRUE(BRepTools::Read(shape, path.c_str(), builder));
  const ImportResult r = import_file(path);
  EXPECT_TRUE(r.complete);
  ASSERT_EQ(r.model.parts.size(), 1u);
  ASSERT_EQ(r.model.instances.size(), 1u);
  const std::string stem = std::filesystem::path(path).stem().string();
  EXPECT_EQ(r.model.parts[0].name, stem);
  EXPECT_EQ(r.model.instances[0].path, "/" + stem);
  EXPECT_EQ(r.model.surfaces.size(), static_cast<std::size_t>(face_count(shape)));
  for (const Surface& s : r.model.surfaces) {
    EXPECT_EQ(s.provenance.kind, SourceKind::BrepFace);
    EXPECT_TRUE(s.has_triangles || has_error(r.diagnostics));
  }
}

INSTANTIATE_TEST_SUITE_P(RealFiles, CadBrep, ::testing::Values("Ball.brep", "Pump_Nut.brep", "bottle.brep", "solid.brep"),
                         [](const auto& param_info) {
                           std::string n = param_info.param;
                           return n.substr(0, n.find('.'));
                         });

}  // namespace
}  // namespace cadclash
