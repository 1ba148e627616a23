// occt_pipeline_peer: the plain OCCT import a FreeCAD or CadQuery user runs, as the peer of
// `cadclash check`'s import in scripts/import_peer_bench.sh (issue 38):
//   occt_pipeline_peer FILE [--deflection 0.1] [--angular 0.5] [--check]
// STEPCAFControl_Reader::ReadFile (read), Transfer into an XCAF document (transfer),
// BRepMesh_IncrementalMesh with its parallel flag on each distinct leaf shape (mesh) and, with
// --check, BRepCheck_Analyzer on each of them, one after another (check). Prints one JSON object.
// Only OCCT: it measures OCCT, nothing of cadclash.
#include <BRepCheck_Analyzer.hxx>
#include <BRepMesh_IncrementalMesh.hxx>
#include <BRep_Tool.hxx>
#include <IFSelect_ReturnStatus.hxx>
#include <Message.hxx>
#include <Message_Messenger.hxx>
#include <Poly_Triangulation.hxx>
#include <STEPCAFControl_Reader.hxx>
#include <Standard_Failure.hxx>
#include <TDF_LabelSequence.hxx>
#include <TDocStd_Document.hxx>
#include <TopExp.hxx>
#include <TopTools_IndexedMapOfShape.hxx>
#include <TopoDS.hxx>
#include <XCAFApp_Application.hxx>
#include <XCAFDoc_DocumentTool.hxx>
#include <XCAFDoc_ShapeTool.hxx>

#include <nlohmann/json.hpp>

#include <sys/resource.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

namespace {

using Clock = std::chrono::steady_clock;

double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

int usage() {
  std::fprintf(stderr, "usage: occt_pipeline_peer FILE [--deflection 0.1] [--angular 0.5] [--check]\n");
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  std::string file;
  double deflection = 0.1, angular = 0.5;
  bool check = false;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--deflection" && i + 1 < argc) {
      deflection = std::atof(argv[++i]);
    } else if (a == "--angular" && i + 1 < argc) {
      angular = std::atof(argv[++i]);
    } else if (a == "--check") {
      check = true;
    } else if (!a.empty() && a[0] != '-' && file.empty()) {
      file = a;
    } else {
      return usage();
    }
  }
  if (file.empty() || !(deflection > 0) || !(angular > 0)) return usage();

  nlohmann::ordered_json result;  // fields in the order a reader expects them
  result["file"] = file;
  std::error_code ec;
  result["size_bytes"] = std::filesystem::file_size(file, ec);
  if (ec) {
    std::fprintf(stderr, "occt_pipeline_peer: cannot open %s\n", file.c_str());
    return 1;
  }
  const Clock::time_point start = Clock::now();
  // OCCT's translators report to stdout; this program's stdout is its JSON object.
  Message::DefaultMessenger()->ChangePrinters().Clear();
  try {
    const Handle(XCAFApp_Application) app = XCAFApp_Application::GetApplication();
    Handle(TDocStd_Document) doc;
    app->NewDocument("MDTV-XCAF", doc);
    STEPCAFControl_Reader reader;
    reader.SetColorMode(true);
    reader.SetNameMode(true);

    Clock::time_point t = Clock::now();
    if (reader.ReadFile(file.c_str()) != IFSelect_RetDone) {
      std::fprintf(stderr, "occt_pipeline_peer: %s: the STEP reader could not parse it\n", file.c_str());
      return 1;
    }
    result["read_s"] = since(t);

    t = Clock::now();
    if (!reader.Transfer(doc)) {
      std::fprintf(stderr, "occt_pipeline_peer: %s: the STEP reader could not transfer it\n", file.c_str());
      return 1;
    }
    result["transfer_s"] = since(t);

    // The distinct leaf shapes: each part once, however many times the assembly places it.
    const Handle(XCAFDoc_ShapeTool) shapes = XCAFDoc_DocumentTool::ShapeTool(doc->Main());
    TDF_LabelSequence labels;
    shapes->GetShapes(labels);
    std::vector<TopoDS_Shape> leaves;
    for (const TDF_Label& l : labels)
      if (XCAFDoc_ShapeTool::IsSimpleShape(l) && !XCAFDoc_ShapeTool::IsAssembly(l)) {
        const TopoDS_Shape s = XCAFDoc_ShapeTool::GetShape(l);
        if (!s.IsNull()) leaves.push_back(s);
      }

    t = Clock::now();
    for (const TopoDS_Shape& s : leaves)
      BRepMesh_IncrementalMesh(s, deflection, /*isRelative=*/false, angular, /*isInParallel=*/true);
    result["mesh_s"] = since(t);

    if (check) {
      t = Clock::now();
      std::size_t invalid = 0;
      for (const TopoDS_Shape& s : leaves)
        if (!BRepCheck_Analyzer(s, /*GeomControls=*/true, /*theIsParallel=*/false).IsValid()) ++invalid;
      result["check_s"] = since(t);
      result["invalid_parts"] = invalid;
    } else {
      result["check_s"] = nullptr;
      result["invalid_parts"] = nullptr;
    }
    result["total_s"] = since(start);

    std::size_t faces = 0, triangles = 0;
    for (const TopoDS_Shape& s : leaves) {
      TopTools_IndexedMapOfShape map;
      TopExp::MapShapes(s, TopAbs_FACE, map);
      faces += static_cast<std::size_t>(map.Extent());
      for (int i = 1; i <= map.Extent(); ++i) {
        TopLoc_Location loc;
        const Handle(Poly_Triangulation)& tri = BRep_Tool::Triangulation(TopoDS::Face(map(i)), loc);
        if (!tri.IsNull()) triangles += static_cast<std::size_t>(tri->NbTriangles());
      }
    }
    result["parts"] = leaves.size();
    result["faces"] = faces;
    result["triangles"] = triangles;
    app->Close(doc);
  } catch (const Standard_Failure& e) {
    std::fprintf(stderr, "occt_pipeline_peer: %s: OCCT failed: %s\n", file.c_str(), e.GetMessageString());
    return 1;
  }
  rusage usage_now{};
  getrusage(RUSAGE_SELF, &usage_now);
  result["peak_rss_mb"] = static_cast<double>(usage_now.ru_maxrss) / 1024.0;  // ru_maxrss is in KiB on Linux
  result["deflection"] = deflection;
  result["angular"] = angular;
  std::printf("%s\n", result.dump().c_str());
  return 0;
}
