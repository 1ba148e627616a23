// make_board_assembly: a printed-circuit-board-like STEP assembly made of real KiCad component models,
// for import benchmarks on large real files (issue 38; docs/import.md, "Large assemblies: the KiCad
// board corpus"; scripts/make_corpus.sh makes the corpus with it).
//   make_board_assembly --out OUT.step --placements N [--seed S] [--name board] [--list FILE] [--verbose]
//                       [--seat MM] [--uncertainty MM] [MODEL.step...]
// The models are the files given (and those listed in FILE, one path a line), in that order. Every
// readable model is placed once, the remaining placements pick models by the seed. Same arguments,
// same geometry, names and colours (OCCT writes the colour styles in an order that follows memory
// addresses, so those lines may come out in another order). --verbose: a line per model on stderr (solids, holes, box).
//
// The structure is the one KiCad 6's STEP exporter (kicad2step) writes, so the file reads like a real
// board export: a root assembly named NAME; the board (an FR4-like plate, 1.6 mm, with drilled
// holes) as product NAME_PCB; one occurrence of the root per placed component, named by its
// reference designator (R1, C7, U3 ...), referring to a product named after the model file's stem;
// that product holds the model's shapes through unnamed occurrences, whose products OCCT names
// itself (SOLID, COMPOUND ...), as kicad2step leaves them. A model placed many times is one product
// referenced many times, as in KiCad.
//
// --seat MM places every component that far above the board's top face (default 0.05; negative: sunk
// into it, as real exports are where a model's body reaches below its origin); the holes stay those
// of the default seat, so pins still clear them. --uncertainty MM writes that length uncertainty
// (UNCERTAINTY_MEASURE_WITH_UNIT; KiCad declares 0.01) instead of OCCT's default.
//
// Only OCCT: this builds in seconds, without cadclash's libraries.
#include <APIHeaderSection_MakeHeader.hxx>
#include <BRepAlgoAPI_Cut.hxx>
#include <BRepAlgoAPI_Common.hxx>
#include <BRepBndLib.hxx>
#include <BRepPrimAPI_MakeBox.hxx>
#include <BRepPrimAPI_MakeCylinder.hxx>
#include <Bnd_Box.hxx>
#include <IFSelect_ReturnStatus.hxx>
#include <Interface_Static.hxx>
#include <Message.hxx>
#include <Message_Messenger.hxx>
#include <Quantity_Color.hxx>
#include <STEPCAFControl_Controller.hxx>
#include <STEPCAFControl_Reader.hxx>
#include <STEPCAFControl_Writer.hxx>
#include <Standard_Failure.hxx>
#include <TDF_LabelSequence.hxx>
#include <TDataStd_Name.hxx>
#include <TCollection_HAsciiString.hxx>
#include <TDocStd_Document.hxx>
#include <XSControl_WorkSession.hxx>
#include <TopExp_Explorer.hxx>
#include <TopLoc_Location.hxx>
#include <TopTools_ListOfShape.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Shape.hxx>
#include <XCAFApp_Application.hxx>
#include <XCAFDoc_ColorTool.hxx>
#include <XCAFDoc_DocumentTool.hxx>
#include <XCAFDoc_ShapeTool.hxx>
#include <XCAFPrs.hxx>
#include <XCAFPrs_IndexedDataMapOfShapeStyle.hxx>
#include <XCAFPrs_Style.hxx>
#include <gp_Ax2.hxx>
#include <gp_Trsf.hxx>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <string>
#include <tuple>
#include <vector>

namespace {

constexpr double kBoardThickness = 1.6;  // mm, the usual FR4 board
constexpr double kSeatHeight = 0.05;     // components sit this far above the board's top face
constexpr double kHoleClearance = 0.1;   // added to each drilled hole's radius
constexpr double kGap = 1.0;             // between neighbouring components
constexpr double kMargin = 3.0;          // between the components and the board's edge
constexpr double kGrid = 0.5;            // placements snap to it, as footprints snap to a grid in KiCad

// splitmix64: the same numbers on every platform and standard library (std distributions are not).
struct Rng {
  std::uint64_t state;
  std::uint64_t next() {
    std::uint64_t z = (state += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  std::size_t below(std::size_t n) { return static_cast<std::size_t>(next() % n); }
};

struct Hole {
  double x, y, r;  // model coordinates
};

struct Model {
  std::string path, stem, prefix;
  TDF_Label product;              // the sub-assembly named after the file's stem
  double xmin, ymin, xmax, ymax;  // model coordinates
  std::vector<Hole> holes;
};

// Reference designator prefix by model family (the library directory, then the file's stem), as
// KiCad's libraries assign them.
std::string designator_prefix(const std::filesystem::path& path) {
  const std::string dir = path.parent_path().filename().string();
  const std::string stem = path.stem().string();
  const auto starts = [](const std::string& s, const char* p) { return s.rfind(p, 0) == 0; };
  static const std::vector<std::pair<const char*, const char*>> by_dir = {
      {"Resistor", "R"},        {"Capacitor", "C"},     {"LED", "D"},          {"Diode", "D"},
      {"Crystal", "Y"},         {"Oscillator", "X"},    {"Inductor", "L"},     {"Connector", "J"},
      {"TerminalBlock", "J"},   {"Package_TO_SOT", "Q"}, {"Package", "U"},      {"Button_Switch", "SW"},
      {"Relay", "K"},           {"Fuse", "F"},          {"Battery", "BT"},     {"Buzzer", "BZ"},
      {"Transformer", "T"},     {"Potentiometer", "RV"}, {"Varistor", "RV"},   {"Display", "DS"},
      {"Mounting", "H"},        {"TestPoint", "TP"},    {"Converter", "PS"},   {"OptoDevice", "U"},
      {"Filter", "FL"},         {"RF", "AE"},           {"Heatsink", "HS"},    {"Sensor", "U"}};
  for (const auto& [d, p] : by_dir)
    if (starts(dir, d)) return p;
  static const std::vector<std::pair<const char*, const char*>> by_stem = {
      {"R_", "R"}, {"C_", "C"}, {"CP_", "C"}, {"LED_", "D"}, {"D_", "D"}, {"Crystal", "Y"}, {"L_", "L"},
      {"PinHeader", "J"}, {"PinSocket", "J"}};
  for (const auto& [s, p] : by_stem)
    if (starts(stem, s)) return p;
  return "U";
}

Bnd_Box exact_box(const TopoDS_Shape& s) {
  Bnd_Box box;
  BRepBndLib::AddOptimal(s, box, /*useTriangulation=*/false, /*useShapeTolerance=*/false);
  return box;
}

// The holes a solid reaching below the board's top face needs. KiCad's models are one solid each,
// body and pins fused, so a hole per solid (its xy box) would be a hole the size of the part: the
// solid is intersected with the board's slab instead (model coordinates: the board's top face is at
// z = -kSeatHeight), and each piece of what lies inside the board (a pin, a peg) gets a hole centred
// on its xy box, radius half that box's diagonal plus the clearance, so the hole clears the piece at
// every depth (pins are often bent or stepped inside the board). If OCCT cannot intersect them, the
// solid gets the hole of its whole xy box.
void add_holes(const TopoDS_Shape& solid, const Bnd_Box& box, std::vector<Hole>& holes) {
  double x0, y0, z0, x1, y1, z1;
  box.Get(x0, y0, z0, x1, y1, z1);
  const TopoDS_Shape slab = BRepPrimAPI_MakeBox(gp_Pnt(x0 - 1, y0 - 1, -kSeatHeight - kBoardThickness),
                                                gp_Pnt(x1 + 1, y1 + 1, -kSeatHeight))
                                .Shape();
  BRepAlgoAPI_Common inside(solid, slab);
  if (!inside.IsDone() || inside.HasErrors()) {
    holes.push_back({(x0 + x1) / 2, (y0 + y1) / 2, std::hypot(x1 - x0, y1 - y0) / 2 + kHoleClearance});
    return;
  }
  for (TopExp_Explorer e(inside.Shape(), TopAbs_SOLID); e.More(); e.Next()) {
    double a0, b0, c0, a1, b1, c1;
    exact_box(e.Current()).Get(a0, b0, c0, a1, b1, c1);
    holes.push_back({(a0 + a1) / 2, (b0 + b1) / 2, std::hypot(a1 - a0, b1 - b0) / 2 + kHoleClearance});
  }
}

// Copies the colours the model's document gives its free shape and sub-shapes (faces, solids, the
// shapes of its assembly's components) onto the leaf label now holding that shape in the board's
// document. kicad2step does the same walk over faces and solids.
void copy_colours(const TDF_Label& source, const Handle(XCAFDoc_ShapeTool)& shapes,
                  const Handle(XCAFDoc_ColorTool)& colours, const TDF_Label& leaf) {
  XCAFPrs_IndexedDataMapOfShapeStyle styles;
  XCAFPrs::CollectStyleSettings(source, TopLoc_Location(), styles);
  const TopoDS_Shape whole = shapes->GetShape(leaf);
  for (int i = 1; i <= styles.Extent(); ++i) {
    const TopoDS_Shape& sub = styles.FindKey(i);
    const XCAFPrs_Style& style = styles.FindFromIndex(i);
    TDF_Label target = leaf;
    if (!sub.IsSame(whole)) {
      TDF_Label existing;
      if (shapes->FindSubShape(leaf, sub, existing))
        target = existing;
      else if (!shapes->AddSubShape(leaf, sub, target))
        continue;  // not a sub-shape of what was copied (cannot happen for a well-formed document)
    }
    if (style.IsSetColorSurf()) colours->SetColor(target, style.GetColorSurf(), XCAFDoc_ColorSurf);
    if (style.IsSetColorCurv()) colours->SetColor(target, style.GetColorCurv(), XCAFDoc_ColorCurv);
  }
}

// Reads one model into its own document and copies its free shapes into a new product of the board's
// document (as kicad2step's transferModel does). False, with the reason, if nothing could be read.
bool load_model(const Handle(XCAFApp_Application)& app, const Handle(TDocStd_Document)& board, Model& m,
                std::string& why, bool verbose) {
  Handle(TDocStd_Document) doc;
  app->NewDocument("MDTV-XCAF", doc);
  bool ok = false;
  std::size_t solids = 0;
  try {
    STEPCAFControl_Reader reader;
    reader.SetColorMode(true);
    reader.SetNameMode(true);
    if (reader.ReadFile(m.path.c_str()) != IFSelect_RetDone) {
      why = "the STEP reader could not parse it";
    } else if (!reader.Transfer(doc)) {
      why = "the STEP reader could not transfer its shapes";
    } else {
      const Handle(XCAFDoc_ShapeTool) src = XCAFDoc_DocumentTool::ShapeTool(doc->Main());
      const Handle(XCAFDoc_ShapeTool) dst = XCAFDoc_DocumentTool::ShapeTool(board->Main());
      const Handle(XCAFDoc_ColorTool) colours = XCAFDoc_DocumentTool::ColorTool(board->Main());
      TDF_LabelSequence free_shapes;
      src->GetFreeShapes(free_shapes);
      Bnd_Box box;
      for (const TDF_Label& label : free_shapes) {
        const TopoDS_Shape shape = src->GetShape(label);
        if (shape.IsNull()) continue;
        if (!ok) {
          m.product = dst->NewShape();
          TDataStd_Name::Set(m.product, TCollection_ExtendedString(m.stem.c_str(), /*isMultiByte=*/true));
          ok = true;
        }
        // expand = false: the model's shape becomes one leaf product, whatever its structure.
        const TDF_Label occurrence = dst->AddComponent(m.product, shape, /*expand=*/false);
        TDF_Label leaf;
        if (dst->GetReferredShape(occurrence, leaf)) copy_colours(label, dst, colours, leaf);
        box.Add(exact_box(shape));
        for (TopExp_Explorer e(shape, TopAbs_SOLID); e.More(); e.Next()) {
          ++solids;
          const Bnd_Box b = exact_box(e.Current());
          if (b.CornerMin().Z() < -kSeatHeight) add_holes(e.Current(), b, m.holes);  // it reaches into the board
        }
      }
      if (!ok) why = "it holds no shape";
      if (ok) {
        double z0, z1;
        box.Get(m.xmin, m.ymin, z0, m.xmax, m.ymax, z1);
      }
    }
  } catch (const Standard_Failure& e) {
    why = std::string("OCCT failed reading it: ") + e.GetMessageString();
    ok = false;
  }
  app->Close(doc);
  if (ok && verbose)
    std::fprintf(stderr, "%s: %s, %zu solids, %zu holes, box %.2f %.2f %.2f %.2f\n", m.path.c_str(), m.stem.c_str(),
                 solids, m.holes.size(), m.xmin, m.ymin, m.xmax, m.ymax);
  return ok;
}

// Rotation by quarter turns about z, with exact cosines (cos(pi/2) is not 0 in floating point).
std::array<double, 2> cos_sin(int quarter) {
  static const std::array<std::array<double, 2>, 4> cs = {{{1, 0}, {0, 1}, {-1, 0}, {0, -1}}};
  return cs[static_cast<std::size_t>(quarter & 3)];
}

std::size_t count_in_file(const std::string& path, const std::string& needle) {
  std::ifstream in(path, std::ios::binary);
  std::string line;
  std::size_t n = 0;
  while (std::getline(in, line))
    if (line.find(needle) != std::string::npos) ++n;
  return n;
}

int usage() {
  std::fprintf(stderr,
               "usage: make_board_assembly --out OUT.step --placements N [--seed S] [--name board] "
               "[--list FILE] [--verbose] [--seat MM] [--uncertainty MM] [MODEL.step...]\n");
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  const auto t0 = std::chrono::steady_clock::now();
  std::string out, name = "board";
  long placements = -1;
  std::uint64_t seed = 1;
  bool verbose = false;
  double seat = kSeatHeight;
  double uncertainty = 0.0;  // 0: OCCT's writer chooses
  std::vector<std::string> paths;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const bool has_value = i + 1 < argc;
    if (a == "--out" && has_value) {
      out = argv[++i];
    } else if (a == "--placements" && has_value) {
      placements = std::strtol(argv[++i], nullptr, 10);
    } else if (a == "--seed" && has_value) {
      seed = std::strtoull(argv[++i], nullptr, 10);
    } else if (a == "--name" && has_value) {
      name = argv[++i];
    } else if (a == "--list" && has_value) {
      std::ifstream list(argv[++i]);
      if (!list) {
        std::fprintf(stderr, "make_board_assembly: cannot open the list %s\n", argv[i]);
        return 2;
      }
      for (std::string line; std::getline(list, line);)
        if (!line.empty() && line[0] != '#') paths.push_back(line);
    } else if (a == "--seat" && has_value) {
      seat = std::strtod(argv[++i], nullptr);
    } else if (a == "--uncertainty" && has_value) {
      uncertainty = std::strtod(argv[++i], nullptr);
      if (!(uncertainty > 0.0)) return usage();
    } else if (a == "--verbose") {
      verbose = true;
    } else if (!a.empty() && a[0] == '-') {
      return usage();
    } else {
      paths.push_back(a);
    }
  }
  if (out.empty() || placements < 1 || paths.empty()) return usage();

  // OCCT's translators report to stdout; this tool's stdout is its summary line.
  Message::DefaultMessenger()->ChangePrinters().Clear();
  STEPCAFControl_Controller::Init();
  const Handle(XCAFApp_Application) app = XCAFApp_Application::GetApplication();
  Handle(TDocStd_Document) board;
  app->NewDocument("MDTV-XCAF", board);
  XCAFDoc_DocumentTool::SetLengthUnit(board, 1.0, UnitsMethods_LengthUnit_Millimeter);
  const Handle(XCAFDoc_ShapeTool) shapes = XCAFDoc_DocumentTool::ShapeTool(board->Main());
  const Handle(XCAFDoc_ColorTool) colours = XCAFDoc_DocumentTool::ColorTool(board->Main());

  // A model read but not placed would be written as a second root, so no more are read than placed.
  std::vector<Model> models;
  for (const std::string& p : paths) {
    if (models.size() == static_cast<std::size_t>(placements)) break;
    Model m;
    m.path = p;
    m.stem = std::filesystem::path(p).stem().string();
    m.prefix = designator_prefix(p);
    std::string why;
    if (load_model(app, board, m, why, verbose))
      models.push_back(std::move(m));
    else
      std::fprintf(stderr, "make_board_assembly: %s: %s; skipped\n", p.c_str(), why.c_str());
  }
  if (models.empty()) {
    std::fprintf(stderr, "make_board_assembly: no model could be read; nothing written\n");
    return 1;
  }

  // Which model each placement is: every model once, then the seed's picks; in the seed's order,
  // so that large and small parts mix on the board as they do on real ones.
  Rng rng{seed};
  std::vector<std::size_t> order;
  for (std::size_t i = 0; i < models.size() && order.size() < static_cast<std::size_t>(placements); ++i)
    order.push_back(i);
  while (order.size() < static_cast<std::size_t>(placements)) order.push_back(rng.below(models.size()));
  for (std::size_t i = order.size(); i > 1; --i) std::swap(order[i - 1], order[rng.below(i)]);

  // Rows of components left to right (shelf packing), rows about as wide as the board is long.
  struct Placement {
    std::size_t model;
    int quarter;
    double tx, ty;
  };
  std::vector<Placement> placed;
  double area = 0, widest = 0;
  std::vector<int> quarters;
  for (std::size_t k = 0; k < order.size(); ++k) {
    quarters.push_back(static_cast<int>(rng.below(4)));
    const Model& m = models[order[k]];
    const double w = (quarters.back() & 1) ? m.ymax - m.ymin : m.xmax - m.xmin;
    const double h = (quarters.back() & 1) ? m.xmax - m.xmin : m.ymax - m.ymin;
    area += (w + kGap) * (h + kGap);
    widest = std::max(widest, w);
  }
  const double row_width = std::max(widest, std::sqrt(area));
  double x = kMargin, y = kMargin, row_height = 0, board_x = 0;
  for (std::size_t k = 0; k < order.size(); ++k) {
    const Model& m = models[order[k]];
    const auto [c, s] = cos_sin(quarters[k]);
    double rx0 = 1e300, ry0 = 1e300, rx1 = -1e300, ry1 = -1e300;
    for (const double px : {m.xmin, m.xmax})
      for (const double py : {m.ymin, m.ymax}) {
        const double qx = c * px - s * py, qy = s * px + c * py;
        rx0 = std::min(rx0, qx), rx1 = std::max(rx1, qx), ry0 = std::min(ry0, qy), ry1 = std::max(ry1, qy);
      }
    if (x > kMargin && x + (rx1 - rx0) > kMargin + row_width) {
      x = kMargin;
      y += row_height + kGap;
      row_height = 0;
    }
    // Snapped up to the grid, so a component never moves onto the one before it.
    const double tx = std::ceil((x - rx0) / kGrid) * kGrid, ty = std::ceil((y - ry0) / kGrid) * kGrid;
    placed.push_back({order[k], quarters[k], tx, ty});
    x = tx + rx1 + kGap;
    row_height = std::max(row_height, ty + ry1 - y);
    board_x = std::max(board_x, tx + rx1);
  }
  const double board_w = board_x + kMargin, board_h = y + row_height + kMargin;

  // The board, drilled where a model's solids reach below its top face (through-hole pins). A hole
  // met twice (two models' pins in the same place) is drilled once.
  std::set<std::tuple<long long, long long, long long>> seen;
  TopTools_ListOfShape drills;
  for (const Placement& p : placed) {
    const auto [c, s] = cos_sin(p.quarter);
    for (const Hole& h : models[p.model].holes) {
      const double hx = c * h.x - s * h.y + p.tx, hy = s * h.x + c * h.y + p.ty;
      if (!seen.emplace(std::llround(hx * 1e6), std::llround(hy * 1e6), std::llround(h.r * 1e6)).second) continue;
      drills.Append(BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(hx, hy, -kBoardThickness - 1), gp::DZ()), h.r,
                                             kBoardThickness + 2)
                        .Shape());
    }
  }
  TopoDS_Shape plate = BRepPrimAPI_MakeBox(gp_Pnt(0, 0, -kBoardThickness), gp_Pnt(board_w, board_h, 0)).Shape();
  if (!drills.IsEmpty()) {
    BRepAlgoAPI_Cut cut;
    TopTools_ListOfShape arguments;
    arguments.Append(plate);
    cut.SetArguments(arguments);
    cut.SetTools(drills);
    cut.SetRunParallel(true);
    cut.Build();
    if (!cut.IsDone()) {
      std::fprintf(stderr, "make_board_assembly: drilling the board's %d holes failed\n", drills.Extent());
      return 1;
    }
    plate = cut.Shape();
  }

  // The tree: root NAME { NAME_PCB, R1 -> stem { => leaf }, ... }.
  const TDF_Label root = shapes->NewShape();
  TDataStd_Name::Set(root, TCollection_ExtendedString(name.c_str(), true));
  const TDF_Label pcb = shapes->AddShape(plate, /*makeAssembly=*/false);
  TDataStd_Name::Set(pcb, TCollection_ExtendedString((name + "_PCB").c_str(), true));
  colours->SetColor(pcb, Quantity_Color(0.20, 0.43, 0.18, Quantity_TOC_RGB), XCAFDoc_ColorSurf);
  const TDF_Label pcb_occurrence = shapes->AddComponent(root, pcb, TopLoc_Location());
  TDataStd_Name::Set(pcb_occurrence, TCollection_ExtendedString((name + "_PCB").c_str(), true));
  std::map<std::string, int> next_number;
  for (const Placement& p : placed) {
    const Model& m = models[p.model];
    const auto [c, s] = cos_sin(p.quarter);
    gp_Trsf t;
    t.SetValues(c, -s, 0, p.tx, s, c, 0, p.ty, 0, 0, 1, seat);
    const TDF_Label occurrence = shapes->AddComponent(root, m.product, TopLoc_Location(t));
    const std::string designator = m.prefix + std::to_string(++next_number[m.prefix]);
    TDataStd_Name::Set(occurrence, TCollection_ExtendedString(designator.c_str(), true));
  }
  shapes->UpdateAssemblies();

  Interface_Static::SetCVal("write.step.schema", "AP214IS");
  Interface_Static::SetCVal("write.step.unit", "MM");
  if (uncertainty > 0.0) {
    Interface_Static::SetIVal("write.precision.mode", 2);  // the value given below
    Interface_Static::SetRVal("write.precision.val", uncertainty);
  }
  STEPCAFControl_Writer writer;
  writer.SetColorMode(true);
  writer.SetNameMode(true);
  if (!writer.Transfer(board, STEPControl_AsIs)) {
    std::fprintf(stderr, "make_board_assembly: could not transfer the board to STEP\n");
    return 1;
  }
  // A fixed header (the time stamp would be now): the same arguments give the same bytes.
  APIHeaderSection_MakeHeader header(writer.ChangeWriter().Model());
  header.SetName(new TCollection_HAsciiString(std::filesystem::path(out).filename().string().c_str()));
  header.SetTimeStamp(new TCollection_HAsciiString("2022-12-16T00:00:00"));
  header.SetOriginatingSystem(new TCollection_HAsciiString("cadclash make_board_assembly"));
  if (writer.Write(out.c_str()) != IFSelect_RetDone) {
    std::fprintf(stderr, "make_board_assembly: could not write %s\n", out.c_str());
    return 1;
  }
  app->Close(board);

  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const auto bytes = std::filesystem::file_size(out);
  std::printf("%s: %zu components, %zu distinct models, %zu faces written, %.2f MB (%ju bytes), %d holes, "
              "board %.0f x %.0f mm, %.1f s\n",
              out.c_str(), placed.size(), models.size(), count_in_file(out, "ADVANCED_FACE("), bytes / 1e6,
              static_cast<std::uintmax_t>(bytes), drills.Extent(), board_w, board_h, seconds);
  return 0;
}
