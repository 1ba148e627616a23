// cadclash/collide.h — the surface-tagged model and the OAABB collision queries over it.
//
// This is the one public header of cadclash::collide. It depends on Eigen and the standard library
// only: a design-review tool can link cadclash::collide without OpenCASCADE or assimp.
//
// Conventions
// - Ids are small integers that index the flat arrays of a Model (parts, surfaces, instances).
// - Units are millimetres; importers convert.
// - Caller mistakes (an id out of range, a malformed Model) are assertions. Untrusted input (files)
//   is reported through Diagnostic values; library code never prints.
#pragma once

#include <Eigen/Geometry>

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace cadclash {

// ---------------------------------------------------------------------------------------------
// Ids and basic geometry
// ---------------------------------------------------------------------------------------------

using PartId = std::uint32_t;
using SurfaceId = std::uint32_t;
using InstanceId = std::uint32_t;
inline constexpr std::uint32_t kInvalidId = ~std::uint32_t{0};

using Vec3 = Eigen::Vector3d;
// Axis-aligned box; a default-constructed box is empty (min > max).
using Aabb = Eigen::AlignedBox3d;
// Rigid transform (rotation + translation) from a part's local frame to the world frame.
using Pose = Eigen::Isometry3d;

// Indexed triangles in double precision, in the owning part's local frame.
struct TriangleMesh {
  std::vector<Vec3> vertices;
  std::vector<std::array<std::uint32_t, 3>> triangles;  // counter-clockwise seen from outside
};

// ---------------------------------------------------------------------------------------------
// Diagnostics: what went wrong in untrusted input, and where
// ---------------------------------------------------------------------------------------------

enum class Severity : std::uint8_t { Warning, Error };

struct Diagnostic {
  Severity severity = Severity::Error;
  std::string file;           // source file path as given by the caller; empty if none
  std::int64_t line = 0;      // 1-based line in `file`; 0 when the format has no lines
  std::int64_t step_id = -1;  // STEP entity #id the message is about; -1 when none
  std::string message;        // one sentence, no trailing newline
};

// Formats a diagnostic as "file:line: error: message" or "file: #id: error: message".
std::string format_diagnostic(const Diagnostic& d);

// Returns true if any diagnostic in `ds` is an error.
bool has_error(std::span<const Diagnostic> ds);

// ---------------------------------------------------------------------------------------------
// The surface-tagged model
// ---------------------------------------------------------------------------------------------

// Where a surface came from.
enum class SourceKind : std::uint8_t {
  StepFace,        // a face of a STEP B-rep; step_id is its ADVANCED_FACE (or FACE_SURFACE) #id
  IgesFace,        // a face of an IGES B-rep; step_id holds the IGES directory entry number if known
  BrepFace,        // a face of an OCCT .brep shape
  ObjGroup,        // an OBJ `g` group or `o` object
  OffColourGroup,  // all faces of an OFF file sharing one face colour
  MeshFile,        // one mesh of an STL/PLY/glTF/... file read whole
  Segment,         // a patch cut out of another surface by segmentation; see Provenance::parent
};

// Returns a stable lower-case name for a source kind ("step-face", "obj-group", ...).
const char* source_kind_name(SourceKind kind);

struct Provenance {
  SourceKind kind = SourceKind::MeshFile;
  std::string source_file;          // file the surface was read from
  std::int64_t step_id = -1;        // STEP entity #id of the face (as written in the file); -1 if none
  std::int32_t face_index = -1;     // index of the face / group / colour within its part, as read
  std::string source_name;          // the file's own name for it (group name, STEP face name); may be empty
  SurfaceId parent = kInvalidId;    // for Segment: the surface this patch was cut from
  std::optional<std::array<float, 3>> colour;  // RGB in [0,1] when the file gives one
  bool healed = false;              // OCCT shape fixing changed the face before tessellation
  bool repaired = false;            // mesh repair changed the surface's triangles
};

class SurfaceSource;

struct Surface {
  std::string name;        // unique within its part
  PartId part = kInvalidId;
  Provenance provenance;
  Aabb aabb;               // part-local; encloses the exact surface (B-rep) or its triangles (mesh)
  double deflection = 0.0; // achieved bound on the distance between triangles and the exact surface; 0 for meshes
  bool has_triangles = false;  // false while a lazy source has not yet been asked for them
  TriangleMesh mesh;       // part-local triangles (empty until has_triangles)
};

struct Part {
  std::string name;
  std::string source_file;
  SurfaceId first_surface = 0;      // surfaces of a part are contiguous: [first_surface, first_surface + surface_count)
  std::uint32_t surface_count = 0;
  // Produces triangles on demand and answers exact-geometry queries; null for parts whose
  // surfaces all carry their triangles (meshes).
  std::shared_ptr<SurfaceSource> source;
};

struct Instance {
  std::string path;  // "/root/sub::2/leaf": names from the root joined by '/', "::k" when a name repeats among siblings
  PartId part = kInvalidId;
  Pose pose = Pose::Identity();  // part-local → world
};

// A whole scene: flat arrays indexed by the ids above.
struct Model {
  std::vector<Part> parts;
  std::vector<Surface> surfaces;
  std::vector<Instance> instances;
};

// Supplies what a part's importer knows beyond triangles: lazy tessellation and exact geometry.
// Implemented in cadclash::tessellate for B-rep parts; collide never sees OCCT.
class SurfaceSource {
 public:
  virtual ~SurfaceSource() = default;

  // Triangulates the part's `local_index`-th surface with a deflection no larger than `deflection`
  // (<= 0 means the source's configured default). Writes triangles in the part's local frame and the
  // achieved deflection. Returns false and fills `error` if the face could not be meshed.
  // Thread-safe for concurrent calls on different parts; calls on one part may serialise.
  virtual bool triangulate(std::uint32_t local_index, double deflection, TriangleMesh& out,
                           double& achieved_deflection, Diagnostic& error) = 0;

  // Exact distance between this part's surface `local_a` placed by `pose_a` and `other`'s surface
  // `local_b` placed by `pose_b`, searching only up to `max_distance` (a value > max_distance means
  // "farther than that"). Returns nullopt when either side has no exact geometry.
  virtual std::optional<double> exact_distance(std::uint32_t local_a, const Pose& pose_a,
                                               const SurfaceSource& other, std::uint32_t local_b,
                                               const Pose& pose_b, double max_distance) const {
    (void)local_a, (void)pose_a, (void)other, (void)local_b, (void)pose_b, (void)max_distance;
    return std::nullopt;
  }
};

// Appends `from` to `into`, shifting its ids. Used to form one scene from several files.
// Instance paths of `from` are prefixed with `path_prefix` (e.g. "/file.stp") when it is not empty.
void append_model(Model& into, Model from, const std::string& path_prefix = {});

// Computes a surface's AABB from its triangles (part-local). Empty box for an empty mesh.
Aabb mesh_aabb(const TriangleMesh& mesh);

// Makes sure every listed surface has triangles, asking its part's SurfaceSource for the missing
// ones (in parallel across parts). Surfaces that fail are listed in the returned diagnostics and
// keep has_triangles == false. `deflection` <= 0 uses each source's default.
// Precondition: every id < model.surfaces.size().
std::vector<Diagnostic> require_triangles(Model& model, std::span<const SurfaceId> surfaces,
                                          double deflection = 0.0);

// Counts triangles over all surfaces that have them.
std::size_t triangle_count(const Model& model);

}  // namespace cadclash
