#include "bench_accuracy_run.h"

#include "cadclash/tessellate.h"

#include <BRepExtrema_ShapeProximity.hxx>
#include <BRep_Builder.hxx>
#include <Standard_Failure.hxx>
#include <TColStd_PackedMapOfInteger.hxx>
#include <TopLoc_Location.hxx>
#include <TopoDS_Compound.hxx>
#include <gp_Trsf.hxx>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <limits>

namespace cadclash::bench {
namespace {

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

Aabb world_box(const Model& m, InstanceId i) {
  const Instance& inst = m.instances[i];
  const Part& p = m.parts[inst.part];
  Aabb local;
  for (SurfaceId s = p.first_surface; s < p.first_surface + p.surface_count; ++s) local.extend(m.surfaces[s].aabb);
  Aabb world;
  if (local.isEmpty()) return world;
  for (int c = 0; c < 8; ++c) world.extend(inst.pose * local.corner(static_cast<Aabb::CornerType>(c)));
  return world;
}

SceneSelection selection_of(const Model& m, const std::function<bool(InstanceId, InstanceId)>& keep) {
  SceneSelection sel;
  if (!keep) return sel;
  // Exclude every pair `keep` rejects; SceneSelection names pairs by instance path.
  for (InstanceId a = 0; a < m.instances.size(); ++a)
    for (InstanceId b = a + 1; b < m.instances.size(); ++b)
      if (!keep(a, b)) sel.excluded_pairs.push_back({m.instances[a].path, m.instances[b].path});
  return sel;
}

DecisionMode decision_of(Mode m) {
  switch (m) {
    case Mode::Fast: return DecisionMode::Fast;
    case Mode::Exact: return DecisionMode::Exact;
    default: return DecisionMode::Certified;
  }
}

RunResult run_cadclash(Model& model, Mode mode, double tolerance, int threads, int repeats,
                       const std::function<bool(InstanceId, InstanceId)>& keep) {
  RunResult out;
  out.mode = mode;
  out.tolerance = tolerance;
  CollideOptions o;
  o.tolerance = tolerance;
  o.threads = threads;
  o.decision = decision_of(mode);
  o.detect_containment = false;  // whole-instance rows have no surface pair to score
  const SceneSelection sel = selection_of(model, keep);
  Report best;
  out.seconds = std::numeric_limits<double>::infinity();
  for (int r = 0; r < std::max(1, repeats); ++r) {
    const auto t0 = std::chrono::steady_clock::now();
    Scene scene(model, sel);
    Report rep = scene.check(o);
    const double t = seconds_since(t0);
    if (t < out.seconds) {
      out.seconds = t;
      best = std::move(rep);
    }
  }
  out.counters = best.counters;
  for (const SurfacePairResult& p : best.pairs) {
    const PairKey k{p.instance_a, p.instance_b, p.surface_a, p.surface_b};
    if (p.contact == ContactClass::Penetrating || p.contact == ContactClass::Touching) out.reported.push_back(k);
    if (p.contact == ContactClass::Undecided) out.undecided.push_back(k);
  }
  return out;
}

// OCCT's proximity tool works on whole shapes: one compound of a part's faces (in local-index order,
// so the tool's face ids are local indices), moved by each instance's pose. It reads the faces'
// current triangulations, which are the ones cadclash's import made.
RunResult run_occt(Model& model, double tolerance, double deflection, int repeats,
                   const std::function<bool(InstanceId, InstanceId)>& keep) {
  RunResult out;
  out.mode = Mode::OcctProximity;
  out.tolerance = tolerance;
  std::vector<TopoDS_Compound> compounds(model.parts.size());
  std::vector<char> has(model.parts.size(), 0);
  BRep_Builder builder;
  for (PartId p = 0; p < model.parts.size(); ++p) {
    const auto* src = dynamic_cast<const BrepSource*>(model.parts[p].source.get());
    if (!src) continue;
    builder.MakeCompound(compounds[p]);
    for (std::uint32_t f = 0; f < src->face_count(); ++f) builder.Add(compounds[p], src->face(f));
    has[p] = 1;
  }
  // The instance pairs a broad phase would hand over: world boxes within tolerance + both deflections.
  std::vector<Aabb> boxes(model.instances.size());
  double max_defl = 0.0;
  for (const Surface& s : model.surfaces) max_defl = std::max(max_defl, s.deflection);
  for (InstanceId i = 0; i < model.instances.size(); ++i) boxes[i] = world_box(model, i);
  std::vector<std::array<InstanceId, 2>> pairs;
  const double gap = tolerance + 2.0 * std::max(max_defl, deflection);
  for (InstanceId a = 0; a < model.instances.size(); ++a)
    for (InstanceId b = a + 1; b < model.instances.size(); ++b) {
      if (!has[model.instances[a].part] || !has[model.instances[b].part]) continue;
      if (keep && !keep(a, b)) continue;
      if (boxes[a].isEmpty() || boxes[b].isEmpty()) continue;
      if (((boxes[a].min() - boxes[b].max()).array() > gap).any() || ((boxes[b].min() - boxes[a].max()).array() > gap).any())
        continue;
      pairs.push_back({a, b});
    }
  out.instance_pairs = pairs.size();
  out.seconds = std::numeric_limits<double>::infinity();
  for (int r = 0; r < std::max(1, repeats); ++r) {
    std::vector<PairKey> found;
    const auto t0 = std::chrono::steady_clock::now();
    for (const auto& [a, b] : pairs) {
      const Instance& ia = model.instances[a];
      const Instance& ib = model.instances[b];
      try {
        BRepExtrema_ShapeProximity prox(tolerance);
        prox.LoadShape1(compounds[ia.part].Moved(TopLoc_Location(truth::to_trsf(ia.pose))));
        prox.LoadShape2(compounds[ib.part].Moved(TopLoc_Location(truth::to_trsf(ib.pose))));
        prox.Perform();
        if (!prox.IsDone()) continue;
        const SurfaceId fa = model.parts[ia.part].first_surface, fb = model.parts[ib.part].first_surface;
        for (BRepExtrema_MapOfIntegerPackedMapOfInteger::Iterator it(prox.OverlapSubShapes1()); it.More(); it.Next())
          for (TColStd_PackedMapOfInteger::Iterator jt(it.Value()); jt.More(); jt.Next())
            found.push_back({a, b, fa + static_cast<SurfaceId>(it.Key()), fb + static_cast<SurfaceId>(jt.Key())});
      } catch (const Standard_Failure&) {
      }
    }
    const double t = seconds_since(t0);
    if (t < out.seconds) out.seconds = t;
    std::sort(found.begin(), found.end());
    out.reported = std::move(found);
  }
  return out;
}

}  // namespace

const char* mode_name(Mode m) {
  switch (m) {
    case Mode::Fast: return "fast";
    case Mode::Certified: return "certified";
    case Mode::Exact: return "exact";
    case Mode::OcctProximity: return "occt-proximity";
  }
  return "?";
}

std::vector<double> decided_shares(const CollideCounters& c) {
  const double n[] = {double(c.decided_mesh),    double(c.decided_mesh_exact), double(c.decided_analytic),
                      double(c.decided_refined), double(c.decided_exact),      double(c.undecided)};
  double total = 0.0;
  for (double v : n) total += v;
  std::vector<double> out;
  for (double v : n) out.push_back(total > 0.0 ? v / total : 0.0);
  return out;
}

std::string decided_shares_text(const CollideCounters& c) {
  const std::vector<double> sh = decided_shares(c);
  if (std::all_of(sh.begin(), sh.end(), [](double v) { return v == 0.0; })) return "-";
  auto percent = [](double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.3g", 100.0 * v);
    return std::string(buf);
  };
  std::string out;
  for (std::size_t i = 0; i < 5; ++i) out += (i ? " / " : "") + percent(sh[i]);
  if (c.undecided) out += " / undecided " + percent(sh[5]);
  return out;
}

RunResult run_mode(Model& model, Mode mode, double tolerance, double deflection, int threads, int repeats,
                   const std::function<bool(InstanceId, InstanceId)>& keep) {
  if (mode == Mode::OcctProximity) return run_occt(model, tolerance, deflection, repeats, keep);
  return run_cadclash(model, mode, tolerance, threads, repeats, keep);
}

}  // namespace cadclash::bench
