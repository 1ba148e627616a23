#include "check_print.h"

#include <cmath>
#include <iomanip>
#include <sstream>
#include <vector>

namespace cadclash::cli {

std::string source_label(const Surface& s) {
  if (s.provenance.step_id >= 0) return "#" + std::to_string(s.provenance.step_id);
  if (!s.provenance.source_name.empty()) return s.provenance.source_name;
  return "face " + std::to_string(s.provenance.face_index);
}

std::string fmt(double v) {
  if (!std::isfinite(v)) return "-";
  std::ostringstream s;
  s << std::setprecision(4) << v;
  return s.str();
}

void print_table(const Model& m, const Report& r, const ClashReview& review, bool collapse, std::ostream& os) {
  const std::vector<const ReportClash*> clash = clash_of_pairs(review, r.pairs.size());
  InstanceId ca = kInvalidId, cb = kInvalidId;
  for (std::size_t k = 0; k < r.pairs.size(); ++k) {
    const SurfacePairResult& p = r.pairs[k];
    if (p.instance_a != ca || p.instance_b != cb) {
      ca = p.instance_a;
      cb = p.instance_b;
      const Instance& a = m.instances[ca];
      const Instance& b = m.instances[cb];
      os << '\n' << a.path << " (" << m.parts[a.part].name << ")  x  " << b.path << " (" << m.parts[b.part].name << ")\n";
      if (clash[k]) os << "  " << clash_heading(review, *clash[k]) << '\n';
      if (!collapse)
        os << "  " << std::left << std::setw(12) << "class" << std::setw(12) << "decided by" << std::setw(11)
           << "distance" << std::setw(34) << "surface A" << "surface B\n";
    }
    if (collapse) continue;
    auto side = [&](SurfaceId s) {
      if (s == kInvalidId) return std::string("(whole part)");
      return m.surfaces[s].name + " [" + source_label(m.surfaces[s]) + "]";
    };
    std::string dist = p.contact == ContactClass::Penetrating ? "-" + fmt(p.penetration) : fmt(p.distance);
    const char* by = p.contact == ContactClass::Containment ? "mesh" : decided_by_name(p.decided_by);
    os << "  " << std::left << std::setw(12) << contact_class_name(p.contact) << std::setw(12) << by << std::setw(11)
       << dist << std::setw(34) << side(p.surface_a) << side(p.surface_b);
    if (p.exact_distance) os << "  exact " << fmt(*p.exact_distance);
    if (p.contact == ContactClass::Undecided)
      os << "  exact distance in [" << fmt(p.distance_lo) << ", " << fmt(p.distance_hi) << "]";
    if (p.within == ContactWithin::ModelUncertainty) {
      auto eps = [&](double e, SurfaceId s) {
        return fmt(e) + " " + uncertainty_source_name(uncertainty_source(m.surfaces[s]));
      };
      os << "  only within the model uncertainty (eps " << eps(p.uncertainty_a, p.surface_a) << " + "
         << eps(p.uncertainty_b, p.surface_b) << ")";
    }
    os << '\n';
  }
}

void print_summary(const Report& r, bool timings, std::ostream& os) {
  ClassCounts n;
  n.add(r);
  const CollideCounters& c = r.counters;
  if (n.c[0] > 0) os << "\n(distance of a penetrating pair: minus its crossing-depth estimate)\n";
  os << "\n" << r.pairs.size() << " reported pairs: " << n.c[0] << " penetrating, " << n.c[1] << " touching, "
     << n.c[2] << " clearance, " << n.c[3] << " containment, " << n.c[4] << " undecided\n";
  std::size_t within[3] = {0, 0, 0};
  for (const SurfacePairResult& p : r.pairs)
    if (p.contact == ContactClass::Penetrating || p.contact == ContactClass::Touching) ++within[static_cast<int>(p.within)];
  if (n.c[0] + n.c[1] > 0)
    os << "contacts within the tolerance " << within[1] << ", only within the model uncertainty " << within[2]
       << ", either " << within[0] << '\n';
  os << "decided by: mesh " << c.decided_mesh << ", mesh-exact " << c.decided_mesh_exact << ", analytic "
     << c.decided_analytic << ", refined " << c.decided_refined << ", exact " << c.decided_exact << ", undecided "
     << c.undecided << "; ambiguous " << c.ambiguous_pairs << ", faces refined " << c.refined_surfaces
     << ", witness queries " << c.witness_queries << ", exact queries " << c.exact_queries << ", dismissed " << c.dismissed_pairs << '\n';
  os << "counters: instance pairs " << c.instance_pairs << ", AABB tests " << c.aabb_tests << ", AABB updates "
     << c.aabb_updates << ", msA " << c.surfaces_a << ", msB " << c.surfaces_b << ", surface pairs " << c.surface_pairs
     << ", mpSk " << c.triangles_a << ", mpSl " << c.triangles_b << ", triangle tests " << c.triangle_tests
     << ", exact fallbacks " << c.exact_fallbacks << ", distance tests " << c.distance_tests
     << ", intersecting surface pairs " << c.intersecting_pairs << ", tessellated on demand "
     << c.tessellated_surfaces << '\n';
  if (timings)
    os << "time: " << fmt(r.timings.total * 1e3) << " ms (broad " << fmt(r.timings.broad * 1e3) << ", surfaces "
       << fmt(r.timings.surface_level * 1e3) << ", tessellation " << fmt(r.timings.tessellation * 1e3)
       << ", triangles " << fmt(r.timings.triangle_level * 1e3) << ")\n";
  if (timings && r.counters.ambiguous_pairs + r.counters.decided_analytic + r.counters.decided_exact > 0)
    os << "decision steps (ms, summed over threads): witnesses " << fmt(r.timings.decide_witness * 1e3) << ", depth "
       << fmt(r.timings.decide_depth * 1e3) << ", refinement " << fmt(r.timings.decide_refine * 1e3) << ", hulls "
       << fmt(r.timings.decide_hull * 1e3) << ", exact " << fmt(r.timings.decide_exact * 1e3) << '\n';
}

std::string stopped_text(const std::string& stopped_by) {
  return stopped_by == kOutOfRange ? "a value outside the supported range (see the errors)" : "the " + stopped_by;
}

void print_partial(const Model& m, const Report& r, std::ostream& os) {
  if (r.complete) return;
  os << "\nPARTIAL REPORT: stopped by " << stopped_text(r.stopped_by) << ": " << r.unexamined_pairs.size() << " of "
     << r.counters.instance_pairs << " instance pairs not examined (or not finished)\n";
  constexpr std::size_t kShown = 10;
  for (std::size_t k = 0; k < r.unexamined_pairs.size() && k < kShown; ++k)
    os << "  not examined: " << m.instances[r.unexamined_pairs[k][0]].path << "  x  "
       << m.instances[r.unexamined_pairs[k][1]].path << '\n';
  if (r.unexamined_pairs.size() > kShown) os << "  ... and " << r.unexamined_pairs.size() - kShown << " more\n";
}

}  // namespace cadclash::cli
