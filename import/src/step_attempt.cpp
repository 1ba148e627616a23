// One attempt at a STEP file (step_attempt.h): its text checked and corrected, the file parsed, the
// model repaired and transferred into an XCAF document, or its faces transferred one by one.
#include "step_attempt.h"

#include "cadclash/internal/byte_io.h"

#include "import_cache.h"
#include "step_model_repairs.h"
#include "step_parallel_transfer.h"
#include "step_piece_cache.h"
#include "step_split_text.h"
#include "step_text.h"
#include "step_uncertainty.h"

#include <IFSelect_ReturnStatus.hxx>
#include <Interface_Static.hxx>
#include <STEPCAFControl_Reader.hxx>
#include <ShapeFix.hxx>
#include <STEPConstruct_Styles.hxx>
#include <StepVisual_Colour.hxx>
#include <StepVisual_StyledItem.hxx>
#include <StepVisual_StyledItemTarget.hxx>
#include <StepRepr_RepresentationItem.hxx>
#include <StepShape_Face.hxx>
#include <TCollection_HAsciiString.hxx>
#include <TDF_LabelSequence.hxx>
#include <TDF_Tool.hxx>
#include <TDocStd_Document.hxx>
#include <TopExp_Explorer.hxx>
#include <TopoDS_Iterator.hxx>
#include <XCAFDoc_ColorTool.hxx>
#include <XCAFDoc_DocumentTool.hxx>
#include <XCAFDoc_ShapeTool.hxx>
#include <XSControl_TransferReader.hxx>
#include <XSControl_WorkSession.hxx>
#include <TransferBRep.hxx>
#include <Transfer_TransientProcess.hxx>

#include <algorithm>
#include <chrono>
#include <ctime>
#include <fstream>
#include <future>
#include <optional>
#include <sstream>
#include <thread>
#include <unordered_map>
#include <utility>

namespace cadclash::detail {
namespace {

const char* status_text(IFSelect_ReturnStatus status) {
  switch (status) {
    case IFSelect_RetVoid: return "the file holds no data";
    case IFSelect_RetDone: return "read";
    case IFSelect_RetError: return "the file could not be opened or is not STEP";
    case IFSelect_RetFail: return "the file could not be parsed";
    case IFSelect_RetStop: return "reading was stopped";
  }
  return "unknown status";
}

// Whether the document holds at least one face: products without any mean the attempt gave nothing.
bool has_faces(const Handle(TDocStd_Document)& doc) {
  TDF_LabelSequence free;
  XCAFDoc_DocumentTool::ShapeTool(doc->Main())->GetFreeShapes(free);
  for (Standard_Integer i = 1; i <= free.Length(); ++i)
    if (TopExp_Explorer(XCAFDoc_ShapeTool::GetShape(free(i)), TopAbs_FACE).More()) return true;
  return false;
}

// Lengths in millimetres, colours and names; the file's other attributes (layers, properties, GD&T,
// materials, views) are not read.
void configure(STEPCAFControl_Reader& reader) {
  Interface_Static::SetCVal("xstep.cascade.unit", "MM");
  reader.SetColorMode(Standard_True);
  reader.SetNameMode(Standard_True);
  reader.SetLayerMode(Standard_False);
  reader.SetPropsMode(Standard_False);
  reader.SetGDTMode(Standard_False);
  reader.SetMatMode(Standard_False);
  reader.SetViewMode(Standard_False);
}

// The file's bytes; empty when it cannot be read.
std::string file_text(const std::string& path) { return file_bytes(path).value_or(std::string()); }

// Parses the file into the reader's model. A truncated file is read up to its last complete entity,
// and references to entities the file does not define are unset first (step_text.h): OCCT then
// reads a corrected copy of `text` instead of the file.
IFSelect_ReturnStatus parse(STEPCAFControl_Reader& reader, const std::string& path, const std::string& text,
                            bool readable, Transfer& result) {
  STEPControl_Reader& step = reader.ChangeReader();
  auto read_text = [&](const std::string& source, bool whole_file) {
    if (auto unset = unset_undefined_references(source, path)) {
      result.diagnostics.insert(result.diagnostics.end(), unset->diagnostics.begin(), unset->diagnostics.end());
      result.complete = false;
      std::istringstream stream(unset->text);
      return step.ReadStream(path.c_str(), stream);
    }
    if (whole_file) return reader.ReadFile(path.c_str());
    std::istringstream stream(source);
    return step.ReadStream(path.c_str(), stream);
  };
  if (!readable) return reader.ReadFile(path.c_str());  // OCCT's own message for a file it cannot open
  if (const auto truncated = close_truncated(text)) {
    result.diagnostics.push_back({Severity::Error, path, truncated->second, -1,
                                  "STEP file is truncated (no END-ISO-10303-21); read up to its last complete entity, "
                                  "which ends on this line"});
    result.complete = false;
    return read_text(truncated->first, false);
  }
  return read_text(text, true);
}

// The #id of an entity of `model` as the file writes it; -1 when it has none.
EntityLabelFn step_labels(const Handle(StepData_StepModel)& model) {
  return [model](const Handle(Standard_Transient)& entity) -> std::int64_t {
    if (model.IsNull()) return -1;
    const Standard_Integer id = model->IdentLabel(entity);
    return id > 0 ? id : -1;
  };
}

// A face entity's #id and name; false for an entity that is no face.
bool describe_face(const Handle(Standard_Transient)& entity, const EntityLabelFn& label, FaceEntity& out) {
  if (!entity->IsKind(STANDARD_TYPE(StepShape_Face))) return false;
  out.id = label(entity);
  const Handle(StepRepr_RepresentationItem) item = Handle(StepRepr_RepresentationItem)::DownCast(entity);
  if (!item.IsNull() && !item->Name().IsNull()) out.name = item->Name()->ToCString();
  return true;
}

// A cut file on its way: pieces the cache holds, and the others parsed by forked workers, a share
// of the pieces each.
struct SplitRead {
  StepSplit split;
  std::vector<std::optional<std::string>> bytes;  // per piece: its shapes, from the cache or a worker
  std::vector<std::vector<std::size_t>> shares;   // per worker: the pieces it reads
  std::optional<Children> workers;
  std::string cache_dir;  // empty: no cache
  std::size_t cached = 0;
  std::chrono::steady_clock::time_point started;  // when the workers were forked
  PieceCosts costs;
};

// CPU seconds of the calling thread (a worker's only thread): what a piece costs wherever it runs.
double thread_cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

// In a worker: each piece of `share` read in turn, their bytes one after another, then each one's
// CPU seconds; "" when one failed.
std::string read_step_pieces(const std::string& path, const std::vector<StepPiece>& pieces, const std::vector<std::size_t>& share) {
  ByteWriter w;
  std::vector<double> seconds;
  for (const std::size_t p : share) {
    const double start = thread_cpu_seconds();
    const std::string bytes = read_step_piece(path, pieces[p]);
    if (bytes.empty()) return {};
    w.str(bytes);
    seconds.push_back(thread_cpu_seconds() - start);
  }
  for (const double s : seconds) w.f64(s);
  return std::move(w.out);
}

// The styled faces of the pieces coloured as STEPCAFControl_Reader::ReadColors colours a face it
// finds styled in the file: on the face's sub-shape label of the part holding it, else on the
// labels of the face's wires. A surface colour that would go to a new sub-shape label of a part
// is kept beside the document instead (`side`: the walk reads it as that label's colour), which
// spares the document a label per face on its way out of the reader and back.
void colour_styled_faces(const Handle(TDocStd_Document)& doc, const std::vector<FaceStyle>& styles,
                         std::vector<SideColour>& side) {
  if (styles.empty() || doc.IsNull()) return;
  const Handle(XCAFDoc_ColorTool) colours = XCAFDoc_DocumentTool::ColorTool(doc->Main());
  const Handle(XCAFDoc_ShapeTool) shapes = XCAFDoc_DocumentTool::ShapeTool(doc->Main());
  auto set = [&](const TDF_Label& label, const FaceStyle& style) {
    if (style.surface) colours->SetColor(label, *style.surface, XCAFDoc_ColorSurf);
    if (style.boundary) colours->SetColor(label, *style.boundary, XCAFDoc_ColorCurv);
    if (style.curve) colours->SetColor(label, *style.curve, XCAFDoc_ColorCurv);
  };
  for (const FaceStyle& style : styles) {
    TDF_Label label;
    if (style.surface && !style.boundary && !style.curve && !shapes->SearchUsingMap(style.face, label, Standard_False, Standard_False)) {
      // Where SearchUsingMap would add the face as a sub-shape (XCAFDoc_ShapeTool::AddSubShape's
      // conditions), unless a label for it is there already.
      const TDF_Label part = shapes->FindMainShapeUsingMap(style.face);
      TDF_Label existing;
      if (!part.IsNull() && shapes->IsSimpleShape(part) && shapes->IsTopLevel(part) && shapes->IsSubShape(part, style.face) &&
          !shapes->FindSubShape(part, style.face, existing)) {
        TCollection_AsciiString entry;
        TDF_Tool::Entry(part, entry);
        Standard_Real r = 0, g = 0, b = 0;
        style.surface->GetRGB().Values(r, g, b, Quantity_TOC_sRGB);
        side.push_back({entry.ToCString(), style.face, {static_cast<float>(r), static_cast<float>(g), static_cast<float>(b)}});
        continue;
      }
    }
    if (shapes->SearchUsingMap(style.face, label, Standard_False, Standard_True)) {
      set(label, style);
      continue;
    }
    for (TopoDS_Iterator it(style.face); it.More(); it.Next())
      if (shapes->SearchUsingMap(it.Value(), label, Standard_False, Standard_True)) set(label, style);
  }
}

// The pieces' shapes bound to the main text's stand-ins, by #id, the workers' stored in the cache:
// false when a worker failed (nothing is bound then).
bool bind_pieces(SplitRead& read, const Handle(StepData_StepModel)& model, const Handle(XSControl_WorkSession)& ws,
                 const EntityLabelFn& label, const std::string& path, ReadBindings& bound, std::vector<Diagnostic>& notes) {
  std::string why;
  // The pieces the cache gave are decoded on a thread of their own while this one waits for the
  // workers (a re-run's changed pieces): each piece apart, joined in piece order below as one pass
  // in piece order makes them; the workers' time stays theirs.
  std::vector<ReadBindings> each(read.bytes.size());
  std::vector<char> decoded(read.bytes.size(), 0);
  bool cached_whole = true;
  auto decode_cached = [&] {
    try {
      for (std::size_t p = 0; p < read.bytes.size() && cached_whole; ++p)
        if (read.bytes[p]) cached_whole = (decoded[p] = read_binding_bytes(*read.bytes[p], each[p], why)) != 0;
    } catch (...) {
      cached_whole = false;
    }
  };
  std::vector<ChildRun> runs;
  if (read.workers) {
    // Joined however the wait ends (a worker's payload too large to hold throws bad_alloc there).
    std::jthread decoding(decode_cached);
    runs = read.workers->wait();
    read.costs.workers = std::chrono::duration<double>(std::chrono::steady_clock::now() - read.started).count();
  } else {
    decode_cached();
  }
  if (!cached_whole) return false;
  for (std::size_t k = 0; k < runs.size(); ++k) {
    const ChildRun& run = runs[k];
    if (!run.isolated || run.crashed || run.payload.empty()) return false;
    ByteReader r{run.payload};
    for (const std::size_t p : read.shares[k]) read.bytes[p] = r.str();
    for (const std::size_t p : read.shares[k]) read.costs.seconds[p] = r.f64();
    if (!r.ok || r.at != run.payload.size()) return false;
  }
  for (std::size_t p = 0; p < read.bytes.size(); ++p) {
    if (!read.bytes[p] || (!decoded[p] && !read_binding_bytes(*read.bytes[p], each[p], why))) return false;
    append_bindings(bound, std::move(each[p]));
  }
  // Stored in piece order until one cannot be (one warning says so, not one per piece).
  if (!read.cache_dir.empty()) {
    std::vector<std::size_t> made;
    for (const auto& share : read.shares) made.insert(made.end(), share.begin(), share.end());
    std::sort(made.begin(), made.end());
    for (const std::size_t p : made)
      if (!store_cached_piece(read.cache_dir, read.split.pieces[p], *read.bytes[p], path, notes)) break;
  }
  std::unordered_map<std::int64_t, Handle(Standard_Transient)> by_id;
  for (const auto& [id, shape] : bound.shapes) by_id.emplace(id, Handle(Standard_Transient)());
  for (Standard_Integer e = 1; e <= model->NbEntities(); ++e)
    if (const auto it = by_id.find(label(model->Value(e))); it != by_id.end()) it->second = model->Value(e);
  std::vector<Handle(Standard_Transient)> entities;
  for (const auto& [id, shape] : bound.shapes) entities.push_back(by_id[id]);
  const Handle(Transfer_TransientProcess) process = ws->TransferReader()->TransientProcess();
  return !process.IsNull() && bind_all(process, entities, bound.shapes, why);
}

// The products into result.doc with the entity of each face, after the repairs that keep OCCT's
// transfer from crashing or dropping products silently (step_model_repairs.h).
void transfer_products(STEPCAFControl_Reader& reader, const Handle(StepData_StepModel)& model,
                       const Handle(XSControl_WorkSession)& ws, const EntityLabelFn& label, const std::string& path,
                       const AttemptRun& run, SplitRead* pieces, Transfer& result) {
  if (run.attempt == Attempt::WithoutBrokenFaces) drop_broken_shapes(model, label, path, result);
  cut_deep_mapped_items(model, label, path, result);
  report_assembly_cycles(model, label, path, result);
  ReadBindings bound;  // the pieces' shapes, held while their faces are tagged
  if (pieces != nullptr) {
    if (!bind_pieces(*pieces, model, ws, label, path, bound, result.diagnostics)) {
      result.split_failed = true;
      return;
    }
    // Reading ends when the slowest piece is parsed (the pieces parse while this process does).
    result.read_seconds = std::max(result.read_seconds, result.split_seconds + bound.parse_seconds);
    result.parallel_workers = std::max<std::size_t>(1, pieces->shares.size());
    result.pieces = pieces->split.pieces.size();
    result.pieces_cached = pieces->cached;
    result.piece_costs = std::move(pieces->costs);
  } else if (run.attempt == Attempt::Whole && run.workers > 1) {
    const ParallelTransfer parallel = transfer_shapes_in_parallel(model, ws, run.workers);
    result.parallel_workers = parallel.used ? parallel.workers : 1;
  }

  // The edges' regularity (XSControl_TransferReader::ShapeResult encodes it on the whole result) was
  // encoded by the workers on each piece's items, the same edges between the same faces, and came
  // back with their shapes: not computed again for every edge of the file here.
  const Standard_Real regularity = Interface_Static::RVal("read.encoderegularity.angle");
  if (pieces != nullptr) Interface_Static::SetRVal("read.encoderegularity.angle", 0.0);
  const std::optional<Handle(Transfer_TransientProcess)> process =
      transfer_document(reader, ws, model, label, path, "STEP", result);
  if (pieces != nullptr) Interface_Static::SetRVal("read.encoderegularity.angle", regularity);
  run.mark(kTransferred);
  if (!process) return;
  colour_styled_faces(result.doc, bound.styles, result.side_colours);
  if (has_faces(result.doc)) run.mark(kShapes);
  result.faces = map_face_entities(
      *process, [&](const Handle(Standard_Transient)& entity, FaceEntity& out) { return describe_face(entity, label, out); },
      bound.tags);
  if (!run.cache_dir.empty()) result.placements = component_placements(result.doc, *process, reader.GetShapeLabelMap(), label);
}

// The parsed model into shapes: its products, or its face entities one by one when the attempt
// says so or the file has no product that can be transferred.
void transfer_model(STEPCAFControl_Reader& reader, const Handle(StepData_StepModel)& model,
                    const Handle(XSControl_WorkSession)& ws, const EntityLabelFn& label, const std::string& path,
                    const AttemptRun& run, SplitRead* pieces, Transfer& result) {
  STEPControl_Reader& step = reader.ChangeReader();
  if (pieces != nullptr && (run.attempt == Attempt::LooseFaces || reader.NbRootsForTransfer() == 0)) {
    result.split_failed = true;  // the stand-ins are no faces to recover: read the whole text
    return;
  }
  if (run.attempt == Attempt::LooseFaces) {
    recover_loose_faces(step, model, path, label, run, "the products could not be transferred", result);
    return;
  }
  if (reader.NbRootsForTransfer() == 0) {
    recover_loose_faces(step, model, path, label, run, "no product structure could be read", result);
    if (!result.loose.IsNull()) return;
    result.diagnostics.push_back({Severity::Error, path, 0, -1,
                                  "STEP file holds no shape to transfer (no product with a shape representation "
                                  "that this reader's schema knows)"});
    result.complete = false;
    return;
  }
  transfer_products(reader, model, ws, label, path, run, pieces, result);
}

}  // namespace

std::string read_step_piece(const std::string& path, const StepPiece& piece) {
  prepare_occt_exchange();
  try {
    STEPCAFControl_Reader reader;
    configure(reader);
    STEPControl_Reader& step = reader.ChangeReader();
    const auto start = std::chrono::steady_clock::now();
    std::istringstream in(piece.text);
    if (step.ReadStream(path.c_str(), in) != IFSelect_RetDone) return {};
    const double parse_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const Handle(StepData_StepModel) model = step.StepModel();
    const Handle(XSControl_WorkSession) ws = step.WS();
    if (model.IsNull() || ws.IsNull() || !ws->ModelCheckList(Standard_False).IsEmpty(Standard_True)) return {};
    std::unordered_map<std::int64_t, Handle(Standard_Transient)> wanted;
    for (const std::int64_t id : piece.reps) wanted.emplace(id, Handle(Standard_Transient)());
    for (const std::int64_t id : piece.bind) wanted.emplace(id, Handle(Standard_Transient)());
    for (Standard_Integer e = 1; e <= model->NbEntities(); ++e)
      if (const auto it = wanted.find(model->IdentLabel(model->Value(e))); it != wanted.end()) it->second = model->Value(e);
    const Handle(XSControl_TransferReader) transfer = ws->TransferReader();
    for (const std::int64_t id : piece.reps) {
      if (wanted[id].IsNull()) return {};
      transfer->TransferOne(wanted[id], Standard_False);
    }
    const Handle(Transfer_TransientProcess) process = transfer->TransientProcess();
    if (process.IsNull() || !process->CheckList(Standard_True).IsEmpty(Standard_True)) return {};
    // The edges' regularity, as the main reader's ShapeResult encodes it on the whole file's result
    // (it then leaves it to the pieces: transfer_products).
    const Standard_Real regularity = Interface_Static::RVal("read.encoderegularity.angle");
    if (regularity > 0)
      for (const std::int64_t id : piece.reps)
        if (const TopoDS_Shape shape = TransferBRep::ShapeResult(process, wanted[id]); !shape.IsNull())
          ShapeFix::EncodeRegularity(shape, regularity);
    ShapeBindings out;
    for (const std::int64_t id : piece.bind) {
      const TopoDS_Shape shape = TransferBRep::ShapeResult(process, wanted[id]);
      if (shape.IsNull()) return {};
      out.bind(id, shape);
    }
    // Every face entity's faces, tagged as the main reader tags its own (transfer_products).
    const EntityLabelFn label = step_labels(model);
    for (Standard_Integer i = 1; i <= process->NbMapped(); ++i) {
      const Handle(Standard_Transient)& entity = process->Mapped(i);
      FaceEntity tag;
      if (entity.IsNull() || !describe_face(entity, label, tag)) continue;
      const TopoDS_Shape shape = TransferBRep::ShapeResult(process->MapItem(i));
      if (shape.IsNull()) continue;
      const bool single = shape.ShapeType() == TopAbs_FACE;
      for (TopExp_Explorer f(shape, TopAbs_FACE); f.More(); f.Next()) out.tag(f.Current(), tag, single);
    }
    // The piece's styled faces (step_split_text.h) and their colours, read as ReadColors reads them
    // from the whole file; the main reader sets them (colour_styled_faces).
    const STEPConstruct_Styles styles(ws);
    for (Standard_Integer e = 1; e <= model->NbEntities(); ++e) {
      const Handle(StepVisual_StyledItem) item = Handle(StepVisual_StyledItem)::DownCast(model->Value(e));
      if (item.IsNull() || item->DynamicType() != STANDARD_TYPE(StepVisual_StyledItem)) continue;
      Handle(StepVisual_Colour) surface, boundary, curve, rendering;
      Standard_Real transparency = 0.0;
      Standard_Boolean component = Standard_False;
      if (!styles.GetColors(item, surface, boundary, curve, rendering, transparency, component)) continue;
      if (item->ItemAP242().IsNull()) continue;
      const Standard_Integer index = process->MapIndex(item->ItemAP242().Value());
      FaceStyle style;
      if (index > 0) style.face = TransferBRep::ShapeResult(process->MapItem(index));
      if (style.face.IsNull()) continue;
      if (!surface.IsNull() || !rendering.IsNull()) {
        Quantity_Color surface_colour, rendering_colour;  // as ReadColors: a colour it cannot decode stays the default
        Quantity_ColorRGBA full;
        if (!surface.IsNull()) {
          STEPConstruct_Styles::DecodeColor(surface, surface_colour);
          full = Quantity_ColorRGBA(surface_colour);
        }
        if (!rendering.IsNull()) {
          STEPConstruct_Styles::DecodeColor(rendering, rendering_colour);
          full = Quantity_ColorRGBA(rendering_colour, static_cast<float>(1.0f - transparency));
        }
        style.surface = full;
      }
      for (auto [from, to] : {std::pair{&boundary, &style.boundary}, std::pair{&curve, &style.curve}}) {
        if (from->IsNull()) continue;
        Quantity_Color colour;
        STEPConstruct_Styles::DecodeColor(*from, colour);
        *to = colour;
      }
      out.style(style);
    }
    return out.bytes(parse_seconds);
  } catch (const Standard_Failure&) {
    return {};
  }
}

Transfer read_step_attempt(const std::string& path, const AttemptRun& attempt_run) {
  prepare_occt_exchange();
  AttemptRun run = attempt_run;
  Transfer result;
  try {
    STEPCAFControl_Reader reader;  // its constructor registers the STEP controller and its parameters
    configure(reader);

    // One read of the text for every scan below; OCCT reads the file (or a corrected copy) itself.
    const auto read_start = std::chrono::steady_clock::now();
    const bool readable = static_cast<bool>(std::ifstream(path));
    const std::string read_here = run.text != nullptr ? std::string() : file_text(path);
    const std::string& text = run.text != nullptr ? *run.text : read_here;
    for (Diagnostic& d : unknown_schemas(text, path)) {
      result.diagnostics.push_back(std::move(d));
      result.complete = false;
    }
    if (text.size() < run.parallel_min_bytes) run.workers = 1;
    // The text's own checks (its unit contexts, its declared uncertainty) run on a thread of their
    // own while the text is cut and parsed (here, when no thread can be started); it is done before
    // this process forks any worker.
    struct TextChecks {
      std::vector<Diagnostic> units, uncertainty;
      double declared = 0.0;
    };
    std::future<TextChecks> text_checks = std::async(std::launch::async | std::launch::deferred, [&text, &path] {
      TextChecks c;
      c.units = unit_context_problems(text, path);
      c.declared = declared_length_uncertainty(text, path, c.uncertainty);
      return c;
    });
    // A large file is cut into pieces that workers parse and transfer while this process parses
    // what is left (step_split_text.h), pieces the cache holds taken from it (step_piece_cache.h);
    // pieces that fail send read_step back to the whole file.
    std::optional<SplitRead> pieces;
    const bool cached = !run.cache_dir.empty();
    if (run.split && run.attempt == Attempt::Whole && (run.workers > 1 || (cached && text.size() >= run.parallel_min_bytes)) && readable) {
      std::string why;
      if (std::optional<StepSplit> split = split_step_text(text, cached, why)) {
        SplitRead& read = pieces.emplace();
        read.split = std::move(*split);
        read.cache_dir = run.cache_dir;
        read.bytes.resize(read.split.pieces.size());
        std::vector<std::size_t> missing;
        for (std::size_t p = 0; p < read.split.pieces.size(); ++p) {
          if (cached) read.bytes[p] = load_cached_piece(run.cache_dir, read.split.pieces[p], path, result.diagnostics);
          if (read.bytes[p]) ++read.cached;
          else missing.push_back(p);
        }
        read.shares = share_pieces(read.split.pieces, missing, run.workers);
        read.costs.seconds.assign(read.split.pieces.size(), 0.0);
        for (const StepPiece& piece : read.split.pieces) {
          read.costs.bytes.push_back(piece.bytes);
          read.costs.weights.push_back(piece.weight);
        }
        text_checks.wait();  // no thread but this one when the workers are forked
        read.started = std::chrono::steady_clock::now();
        read.costs.split = std::chrono::duration<double>(read.started - read_start).count();
        if (!read.shares.empty())
          read.workers.emplace(read.shares.size(), [&](std::size_t k, const Mark&) {
            return read_step_pieces(path, read.split.pieces, read.shares[k]);
          });
      }
      result.split_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - read_start).count();
    }
    IFSelect_ReturnStatus status;
    if (pieces) {
      std::istringstream main_text(pieces->split.main_text);
      const double parse_start = thread_cpu_seconds();
      status = reader.ChangeReader().ReadStream(path.c_str(), main_text);
      pieces->costs.main_parse = thread_cpu_seconds() - parse_start;
    } else {
      status = parse(reader, path, text, readable, result);
    }
    result.read_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - read_start).count();
    STEPControl_Reader& step = reader.ChangeReader();
    const Handle(StepData_StepModel) model = step.StepModel();
    const EntityLabelFn label = step_labels(model);
    const Handle(XSControl_WorkSession) ws = step.WS();
    std::size_t load_fails = 0;
    if (!ws.IsNull() && !model.IsNull() && model->NbEntities() > 0)
      load_fails = append_checks(ws->ModelCheckList(Standard_False), model, label, path, "STEP syntax", false,
                                 result.diagnostics);
    if (status != IFSelect_RetDone) {
      result.diagnostics.push_back({Severity::Error, path, 0, -1, std::string("cannot read STEP file: ") + status_text(status)});
      result.complete = false;
      return result;
    }
    run.mark(kParsed);
    if (load_fails > 0) result.complete = false;
    TextChecks checked = text_checks.get();
    for (Diagnostic& d : checked.units) {
      if (d.severity == Severity::Error) result.complete = false;
      result.diagnostics.push_back(std::move(d));
    }
    result.declared_uncertainty = checked.declared;
    for (Diagnostic& d : checked.uncertainty) result.diagnostics.push_back(std::move(d));
    if (model.IsNull() || model->NbEntities() == 0) {
      result.diagnostics.push_back({Severity::Error, path, 0, -1, "STEP file has an empty DATA section"});
      result.complete = false;
      return result;
    }
    transfer_model(reader, model, ws, label, path, run, pieces ? &*pieces : nullptr, result);
  } catch (const Standard_Failure& e) {
    record_occt_failure(result, path, "STEP", e);
  }
  return result;
}

}  // namespace cadclash::detail
