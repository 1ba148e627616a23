// B-rep edge cases on small files: a face BRepCheck rejects is healed, a face BRepMesh cannot mesh is
// kept and reported, and STEP face colours match the COLOUR_RGB values written in the file.
// data/cad/heal_unshared_vertices.brep, mesh_fail_bowtie.brep and mesh_fail_degenerate.step were
// written with OCCT 7.6 (BRepTools::Write, STEPControl_Writer) from the shapes the comments below describe.
#include "cadclash/collide.h"
#include "cadclash/import.h"
#include "import_compare.h"

#include <BRepCheck_Analyzer.hxx>
#include <BRepTools.hxx>
#include <BRep_Builder.hxx>
#include <TopExp.hxx>
#include <TopTools_IndexedMapOfShape.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Shape.hxx>

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <sstream>

#include <stdlib.h>

namespace cadclash {
namespace {

const std::string kCad = std::string(CADCLASH_DATA_DIR) + "/cad/";
const std::string kExternal = std::string(CADCLASH_DATA_DIR) + "/external/";

std::string slurp(const std::string& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

double mesh_area(const TriangleMesh& mesh) {
  double area = 0.0;
  for (const auto& t : mesh.triangles)
    area += 0.5 * (mesh.vertices[t[1]] - mesh.vertices[t[0]]).cross(mesh.vertices[t[2]] - mesh.vertices[t[0]]).norm();
  return area;
}

// BRepCheck's verdict on each face of the file, in face-index order (TopExp::MapShapes, as the importer).
std::vector<bool> faces_valid(const std::string& brep) {
  TopoDS_Shape shape;
  BRep_Builder builder;
  if (!BRepTools::Read(shape, brep.c_str(), builder)) return {};
  TopTools_IndexedMapOfShape faces;
  TopExp::MapShapes(shape, TopAbs_FACE, faces);
  std::vector<bool> out;
  for (Standard_Integer i = 1; i <= faces.Extent(); ++i)
    out.push_back(BRepCheck_Analyzer(faces(i), Standard_True).IsValid() == Standard_True);
  return out;
}

std::string describe(const std::vector<Diagnostic>& ds) {
  std::string s;
  for (const Diagnostic& d : ds) s += format_diagnostic(d) + "\n";
  return s;
}

// The clashes of an assembly's faces as translated without OCCT's healing at transfer
// (ImportOptions::transfer_healing = false) are those of the healed ones: on as1 the faces BRepCheck
// then rejects are healed one by one, each named by its STEP #id in a warning; with healing none is.
TEST(CadHeal, WithoutHealingAtTransferAs1sClashesStayAndHealedFacesAreNamed) {
  const std::string path = kExternal + "as1-tu-203.stp";
  if (!std::filesystem::exists(path)) GTEST_SKIP() << "run scripts/setup.sh";
  std::vector<std::vector<std::string>> pairs;
  std::vector<std::size_t> healed_faces;
  for (const bool healing : {true, false}) {
    SCOPED_TRACE(healing ? "healing at transfer" : "no healing at transfer");
    ImportOptions options;
    options.transfer_healing = healing;
    ImportResult r = import_file(path, options);
    EXPECT_TRUE(r.complete) << describe(r.diagnostics);
    std::size_t healed = 0;
    for (const Diagnostic& d : r.diagnostics) {
      EXPECT_NE(d.severity, Severity::Error) << format_diagnostic(d);
      if (d.message.find("failed BRepCheck; healed with ShapeFix_Face") == std::string::npos) continue;
      EXPECT_GT(d.step_id, 0) << format_diagnostic(d);
      ++healed;
    }
    std::size_t flagged = 0;
    for (const Surface& s : r.model.surfaces) flagged += s.provenance.healed;
    EXPECT_EQ(flagged, healed);
    healed_faces.push_back(healed);
    Scene scene(r.model, SceneSelection{});
    CollideOptions o;
    o.tolerance = 0.01;
    const auto result = scene.check(o);
    EXPECT_TRUE(result.complete);
    std::vector<std::string> names;
    for (const SurfacePairResult& p : result.pairs)
      names.push_back(std::to_string(p.instance_a) + "/" + std::to_string(p.surface_a) + " " +
                      std::to_string(p.instance_b) + "/" + std::to_string(p.surface_b) + " " + std::to_string(static_cast<int>(p.contact)));
    std::sort(names.begin(), names.end());
    pairs.push_back(std::move(names));
  }
  EXPECT_EQ(healed_faces[0], 0u);
  EXPECT_GT(healed_faces[1], 0u);
  EXPECT_FALSE(pairs[0].empty());
  EXPECT_EQ(pairs[0], pairs[1]);
}

// OCCT heals a transferred shape with the parameters of the resource file the environment names
// (CSF_STEPDefaults, CSF_IGESDefaults), and with its defaults when none is named. With OCCT's own
// STEP resource named, t20_data.step's faces mesh differently in the last bits (its pcurves come out
// of the resource's sequence rounded otherwise): cadclash heals the same way whatever the
// environment names, so the same file gives the same model on every machine.
TEST(CadHeal, TheEnvironmentsHealingResourceChangesNothing) {
  const std::string path = kExternal + "t20_data.step";
  const std::string resources = "/usr/share/opencascade/resources/XSTEPResource";  // occt-misc
  if (!std::filesystem::exists(path)) GTEST_SKIP() << "run scripts/setup.sh";
  if (!std::filesystem::exists(resources + "/STEP")) GTEST_SKIP() << "OCCT's STEP resource file is missing (occt-misc)";
  const ImportResult plain = import_file(path);
  ::setenv("CSF_STEPDefaults", resources.c_str(), 1);
  const ImportResult named = import_file(path);
  ::unsetenv("CSF_STEPDefaults");
  ASSERT_TRUE(plain.complete) << describe(plain.diagnostics);
  EXPECT_TRUE(testing_import::same_bytes(testing_import::everything(named), testing_import::everything(plain)));
}

// Face 0: a valid 10 x 10 square at x in [20, 30]. Face 1: a 10 x 10 square at the origin whose four
// edges each carry their own end vertices (coincident, not shared), as some exporters write them.
TEST(CadHeal, InvalidFaceIsHealedAndTessellated) {
  const std::string path = kCad + "heal_unshared_vertices.brep";
  // The fixture really is what the test needs: BRepCheck accepts face 0 and rejects face 1.
  ASSERT_EQ(faces_valid(path), (std::vector<bool>{true, false}));

  for (const bool lazy : {false, true}) {
    SCOPED_TRACE(lazy ? "lazy" : "eager");
    ImportOptions options;
    options.lazy = lazy;
    ImportResult r = import_file(path, options);
    ASSERT_EQ(r.model.surfaces.size(), 2u) << describe(r.diagnostics);
    EXPECT_TRUE(r.complete) << describe(r.diagnostics);
    EXPECT_FALSE(r.model.surfaces[0].provenance.healed);
    EXPECT_TRUE(r.model.surfaces[1].provenance.healed);
    if (lazy) {
      const std::vector<SurfaceId> all{0, 1};
      const std::vector<Diagnostic> failed = require_triangles(r.model, all);
      EXPECT_TRUE(failed.empty()) << describe(failed);
    }
    for (const Surface& s : r.model.surfaces) {
      ASSERT_TRUE(s.has_triangles) << s.name;
      EXPECT_NEAR(mesh_area(s.mesh), 100.0, 1e-9) << s.name;
    }
    const Aabb& box = r.model.surfaces[1].aabb;
    EXPECT_NEAR(box.min().x(), 0.0, 1e-6);
    EXPECT_NEAR(box.max().x(), 10.0, 1e-6);
    EXPECT_NEAR(box.max().y(), 10.0, 1e-6);

    // One warning, naming the healed face and its part; nothing about the valid face.
    std::size_t heal_warnings = 0;
    for (const Diagnostic& d : r.diagnostics) {
      EXPECT_EQ(d.message.find("face 0 "), std::string::npos) << d.message;
      if (d.message.find("face 1 of part 'heal_unshared_vertices' failed BRepCheck; healed with ShapeFix_Face") !=
          std::string::npos) {
        EXPECT_EQ(d.severity, Severity::Warning);
        EXPECT_EQ(d.file, path);
        ++heal_warnings;
      }
    }
    EXPECT_EQ(heal_warnings, 1u) << describe(r.diagnostics);
  }
}

// Imports a file of two faces: a valid 10 x 10 square at x in [20, 30] and one BRepMesh cannot mesh
// at x in [0, 10]. The failed face must keep its surface (exact box, no triangles), make the result
// incomplete, and get exactly one Error naming its index, its part and its entity id. Returns it.
Surface expect_one_face_unmeshed(const std::string& path, ImportResult& r) {
  r = import_file(path);
  EXPECT_EQ(r.model.surfaces.size(), 2u) << describe(r.diagnostics);
  EXPECT_FALSE(r.complete);
  const Surface* meshed = nullptr;
  const Surface* failed = nullptr;
  for (const Surface& s : r.model.surfaces) (s.has_triangles ? meshed : failed) = &s;
  if (meshed == nullptr || failed == nullptr) {
    ADD_FAILURE() << "expected one meshed and one failed face\n" << describe(r.diagnostics);
    return {};
  }
  EXPECT_TRUE(failed->mesh.triangles.empty());
  EXPECT_NEAR(mesh_area(meshed->mesh), 100.0, 1e-9);
  EXPECT_GT(meshed->aabb.min().x(), 19.9);  // the valid square is the one meshed
  EXPECT_FALSE(failed->aabb.isEmpty());     // the failed one keeps its exact box
  EXPECT_NEAR(failed->aabb.max().x(), 10.0, 1e-6);

  const std::string part = r.model.parts[failed->part].name;
  const std::string named = "face " + std::to_string(failed->provenance.face_index) + " of part '" + part + "'";
  std::size_t errors = 0;
  for (const Diagnostic& d : r.diagnostics) {
    if (d.severity != Severity::Error) continue;
    ++errors;
    EXPECT_NE(d.message.find(named), std::string::npos) << d.message;
    EXPECT_NE(d.message.find("could not be tessellated"), std::string::npos) << d.message;
    EXPECT_EQ(d.file, path);
    EXPECT_EQ(d.step_id, failed->provenance.step_id);
  }
  EXPECT_EQ(errors, 1u) << describe(r.diagnostics);
  return *failed;
}

// Face 1 is a "bow tie": its wire (0,0) → (10,10) → (10,0) → (0,10) crosses itself at (5,5).
// BRepCheck rejects it, ShapeFix_Face leaves it as it is, and BRepMesh refuses a self-intersecting wire.
TEST(CadMeshFailure, SelfIntersectingFaceKeptAndReported) {
  const std::string path = kCad + "mesh_fail_bowtie.brep";
  ASSERT_EQ(faces_valid(path), (std::vector<bool>{true, false}));
  ImportResult r;
  const Surface failed = expect_one_face_unmeshed(path, r);
  EXPECT_EQ(failed.provenance.face_index, 1);
  EXPECT_EQ(failed.provenance.step_id, -1);  // a .brep has no entity ids: the face index names it
  // BRepCheck's rejection is reported too, naming the same face.
  std::size_t check_warnings = 0;
  for (const Diagnostic& d : r.diagnostics)
    if (d.severity == Severity::Warning &&
        d.message.find("face 1 of part 'mesh_fail_bowtie' failed BRepCheck") != std::string::npos)
      ++check_warnings;
  EXPECT_EQ(check_warnings, 1u) << describe(r.diagnostics);
}

// ADVANCED_FACE #132 lies on a B_SPLINE_SURFACE_WITH_KNOTS #137 whose rows of poles coincide: the
// surface collapses onto the segment (0,0,0)-(10,0,0). BRepCheck accepts it, the STEP reader keeps it,
// and BRepMesh gives it no triangles. #39 is the valid square.
TEST(CadMeshFailure, DegenerateStepFaceKeptAndReportedWithItsId) {
  const std::string path = kCad + "mesh_fail_degenerate.step";
  const std::string text = slurp(path);
  ASSERT_NE(text.find("#132 = ADVANCED_FACE('',(#133),#137,.T.);"), std::string::npos);
  ASSERT_NE(text.find("#39 = ADVANCED_FACE("), std::string::npos);
  ImportResult r;
  const Surface failed = expect_one_face_unmeshed(path, r);
  EXPECT_EQ(failed.provenance.step_id, 132);
  for (const Surface& s : r.model.surfaces) {
    if (s.has_triangles) {
      EXPECT_EQ(s.provenance.step_id, 39);
    }
  }
}

// The COLOUR_RGB entities of a STEP file, by #id, read from its text.
std::map<std::int64_t, std::array<double, 3>> colour_rgbs(const std::string& text) {
  std::map<std::int64_t, std::array<double, 3>> out;
  const std::regex entity(R"(#(\d+)\s*=\s*COLOUR_RGB\s*\(\s*'[^']*'\s*,\s*([-+.\dEe]+)\s*,\s*([-+.\dEe]+)\s*,\s*([-+.\dEe]+)\s*\))");
  for (auto it = std::sregex_iterator(text.begin(), text.end(), entity); it != std::sregex_iterator(); ++it)
    out[std::stoll((*it)[1].str())] = {std::stod((*it)[2].str()), std::stod((*it)[3].str()), std::stod((*it)[4].str())};
  return out;
}

void expect_colour(const Surface& s, const std::array<double, 3>& want) {
  ASSERT_TRUE(s.provenance.colour.has_value()) << "#" << s.provenance.step_id;
  for (int c = 0; c < 3; ++c)
    EXPECT_NEAR((*s.provenance.colour)[static_cast<std::size_t>(c)], want[static_cast<std::size_t>(c)], 1e-6)
        << "#" << s.provenance.step_id << " channel " << c;
}

// step_boundary_colors.stp: solid #21 is styled COLOUR_RGB #22 (grey 0.882352941176); over-riding
// styles give face #70 'green', #162 'red' (DRAUGHTING_PRE_DEFINED_COLOUR) and #194 COLOUR_RGB #195
// (0, 0.501960784314, 1). Colours are stored as the file writes them (sRGB components), not linearised.
TEST(CadColour, StepFaceColoursMatchFile) {
  const std::string path = kExternal + "step_boundary_colors.stp";
  if (!std::filesystem::exists(path)) GTEST_SKIP() << path << " missing: run scripts/setup.sh";
  const auto rgb = colour_rgbs(slurp(path));
  ASSERT_EQ(rgb.count(22), 1u);
  ASSERT_EQ(rgb.count(195), 1u);
  ASSERT_NEAR(rgb.at(195)[1], 0.501960784314, 1e-12);  // the regex read the file as this test expects

  ImportOptions options;
  options.tessellation.linear_deflection = 1.0;
  const ImportResult r = import_file(path, options);
  ASSERT_FALSE(r.model.surfaces.empty()) << describe(r.diagnostics);
  std::set<std::int64_t> seen;
  for (const Surface& s : r.model.surfaces) {
    const std::int64_t id = s.provenance.step_id;
    seen.insert(id);
    if (id == 194) expect_colour(s, rgb.at(195));
    else if (id == 70) expect_colour(s, {0.0, 1.0, 0.0});
    else if (id == 162) expect_colour(s, {1.0, 0.0, 0.0});
    else expect_colour(s, rgb.at(22));
  }
  for (const std::int64_t id : {70, 162, 194}) EXPECT_EQ(seen.count(id), 1u) << "#" << id;
}

// DRAUGHTING_PRE_DEFINED_COLOUR names a file uses, as RGB (ISO 10303-46 predefined colours).
std::vector<std::array<double, 3>> predefined_colours(const std::string& text) {
  static const std::map<std::string, std::array<double, 3>> kNamed = {
      {"black", {0, 0, 0}}, {"red", {1, 0, 0}},     {"green", {0, 1, 0}},   {"blue", {0, 0, 1}},
      {"yellow", {1, 1, 0}}, {"magenta", {1, 0, 1}}, {"cyan", {0, 1, 1}}, {"white", {1, 1, 1}}};
  std::vector<std::array<double, 3>> out;
  const std::regex entity(R"(DRAUGHTING_PRE_DEFINED_COLOUR\s*\(\s*'([a-z]+)'\s*\))");
  for (auto it = std::sregex_iterator(text.begin(), text.end(), entity); it != std::sregex_iterator(); ++it)
    if (auto named = kNamed.find((*it)[1].str()); named != kNamed.end()) out.push_back(named->second);
  return out;
}

// as1-tu-203.stp colours whole products, by COLOUR_RGB (#2176 orange, #2224 olive) and by predefined
// names: every coloured surface must carry one of the colours the file writes, and both RGB ones occur.
TEST(CadColour, As1ColoursAreFileColours) {
  const std::string path = kExternal + "as1-tu-203.stp";
  if (!std::filesystem::exists(path)) GTEST_SKIP() << path << " missing: run scripts/setup.sh";
  const std::string text = slurp(path);
  const auto rgb = colour_rgbs(text);
  ASSERT_EQ(rgb.size(), 2u);
  std::vector<std::pair<std::int64_t, std::array<double, 3>>> allowed(rgb.begin(), rgb.end());
  for (const auto& c : predefined_colours(text)) allowed.emplace_back(-1, c);
  ImportOptions options;
  options.lazy = true;  // colours come from the document; no triangles needed
  const ImportResult r = import_file(path, options);
  std::set<std::int64_t> rgb_used;
  std::size_t coloured = 0;
  for (const Surface& s : r.model.surfaces) {
    if (!s.provenance.colour) continue;
    ++coloured;
    bool found = false;
    for (const auto& [id, c] : allowed) {
      bool same = true;
      for (std::size_t k = 0; k < 3; ++k) same = same && std::abs((*s.provenance.colour)[k] - c[k]) <= 1e-6;
      if (!same) continue;
      found = true;
      if (id >= 0) rgb_used.insert(id);
    }
    EXPECT_TRUE(found) << "#" << s.provenance.step_id << " has a colour the file does not write";
  }
  EXPECT_GT(coloured, 0u);
  EXPECT_EQ(rgb_used, (std::set<std::int64_t>{2176, 2224}));
}

}  // namespace
}  // namespace cadclash
