// The name of every value of the enums collide.h declares, as the JSON report and the CLI spell them.
#include "cadclash/collide.h"

namespace cadclash {

const char* contact_class_name(ContactClass c) {
  switch (c) {
    case ContactClass::Penetrating: return "penetrating";
    case ContactClass::Touching: return "touching";
    case ContactClass::Clearance: return "clearance";
    case ContactClass::Containment: return "containment";
    case ContactClass::Undecided: return "undecided";
  }
  return "unknown";
}

const char* decided_by_name(DecidedBy d) {
  switch (d) {
    case DecidedBy::Mesh: return "mesh";
    case DecidedBy::MeshExact: return "mesh-exact";
    case DecidedBy::Analytic: return "analytic";
    case DecidedBy::Refined: return "refined";
    case DecidedBy::Exact: return "exact";
    case DecidedBy::Undecided: return "undecided";
  }
  return "unknown";
}

const char* contact_within_name(ContactWithin w) {
  switch (w) {
    case ContactWithin::Unknown: return "unknown";
    case ContactWithin::Tolerance: return "tolerance";
    case ContactWithin::ModelUncertainty: return "model uncertainty";
  }
  return "unknown";
}

const char* decision_mode_name(DecisionMode m) {
  switch (m) {
    case DecisionMode::Certified: return "certified";
    case DecisionMode::Fast: return "fast";
    case DecisionMode::Exact: return "exact";
  }
  return "unknown";
}

const char* progress_stage_name(ProgressStage s) {
  switch (s) {
    case ProgressStage::ReadFile: return "read file";
    case ProgressStage::TessellatePart: return "tessellate part";
    case ProgressStage::CheckPairs: return "check instance pairs";
    case ProgressStage::TrajectoryStep: return "trajectory step";
    case ProgressStage::CheckPart: return "check part";
  }
  return "unknown";
}

const char* collide_mode_name(CollideMode m) {
  return m == CollideMode::AllTrianglePairs ? "all-triangle-pairs" : "early-exit";
}

const char* parallel_version_name(ParallelVersion v) { return v == ParallelVersion::V2 ? "v2" : "v1"; }

const char* schedule_name(Schedule s) {
  switch (s) {
    case Schedule::Dynamic: return "dynamic";
    case Schedule::Static: return "static";
    case Schedule::Guided: break;
  }
  return "guided";
}

const char* triangle_level_name(TriangleLevel t) {
  switch (t) {
    case TriangleLevel::Flat: return "flat";
    case TriangleLevel::Bvh: return "bvh";
    case TriangleLevel::Auto: break;
  }
  return "auto";
}

}  // namespace cadclash
