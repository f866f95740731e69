// Frame fields solved from sketches (Zhang §3), stored as revisions: creation is revision 1,
// every added or removed curve makes the next revision (data_store.h: fields/<id>/r<N>.stf + r<N>.json).
// A revision never changes once written, and volumes copy the revision they use, so adding a
// curve never alters an existing volume. The solver of a recently used field stays in memory
// so that adding a curve re-solves incrementally (warm start); after a restart the first added
// curve re-solves the stored sketch first. Solves poll the interrupter throughout (FieldSolver:
// at every conjugate-gradient iteration), and grids beyond config.max_field_nodes are
// refused before anything is allocated.
// Reads go through the store (several replicas on one store, README): a field created
// through another replica is loaded, a revision added through another is taken up at the next
// access, and a field deleted through another answers 404. A failure of the store is answered
// as such (kUnavailable from S3: 502); list() then shows what this replica knows.
// Thread-safe; operations on one field are serialised within one replica, and across replicas
// by the store: a revision's files are write-once, so of two changes of one field made at once
// through two replicas the later one fails with kFailedPrecondition naming "revision" (409)
// and changes nothing.
#pragma once

#include <nlohmann/json.hpp>

#include <memory>
#include <optional>
#include <string>

#include "storage.h"
#include "field/field_file.h"
#include "core/interrupter.h"
#include "mesh/mesh.h"
#include "server_config.h"

namespace solidtex::server {

// A field derived from a mesh's geometry (mesh_geometry.h): its domain is the placed mesh's
// box enlarged by `margin`, and the constraints become an ordinary sketch (frames and/or
// curves), stored and extendable like any other.
struct MeshFieldOptions {
  enum class Kind { kCurvature, kFeatures };
  Kind kind = Kind::kCurvature;
  Placement placement;
  double margin = 0.25;
  int shortest_side_cells = 24;   // [2, 256]
  int max_constraints = 2000;     // curvature frames, [1, 20000]
  double feature_angle_degrees = 60;
  std::vector<std::vector<std::array<double, 3>>> curves;  // user polylines, mesh coordinates
};

class FieldService {
 public:
  FieldService(Storage& store, const ServerConfig& config);
  ~FieldService();

  Status start(std::vector<std::string>* report);
  Result<nlohmann::json> create(const std::string& sketch_json, Interrupter& interrupter);
  Result<nlohmann::json> create_from_mesh(const Mesh& mesh, const MeshFieldOptions& options, Interrupter& interrupter);
  // Changes of one field (add_curve, remove_last_curve, remove) wait for each other, polling
  // `interrupter` every 50 ms meanwhile: kCancelled when it asks to stop before their turn.
  // `expected_revision`, when given, must be the field's current revision, checked once it is
  // this call's turn: else kFailedPrecondition naming "revision" (saying the current one) and
  // nothing changes, so that a client never adds to or undoes a sketch it has not seen.
  Result<nlohmann::json> add_curve(const std::string& id, const std::string& curve_json, Interrupter& interrupter,
                                   std::optional<int> expected_revision = std::nullopt);
  // Undo of add_curve: the next revision holds the sketch without its last curve, equal bit for
  // bit to the newest earlier revision with exactly those curves (earlier revisions that cannot
  // be read are passed over; the scan polls `interrupter`), or solved afresh when there is none.
  // kFailedPrecondition when the sketch has no curve, or when its only curve would leave it
  // with neither curves nor frames.
  Result<nlohmann::json> remove_last_curve(const std::string& id, Interrupter& interrupter,
                                           std::optional<int> expected_revision = std::nullopt);
  Result<nlohmann::json> get(const std::string& id) const;
  nlohmann::json list() const;
  // Waits for a running add_curve or remove_last_curve of the field to finish (as above).
  Status remove(const std::string& id, Interrupter& interrupter);
  // The current revision's .stf bytes, and its number.
  Result<std::vector<uint8_t>> file_bytes(const std::string& id, int* revision = nullptr) const;
  // Frames (and scales) at min + step * (i, j, k) for i < size[0], j < size[1], k < size[2].
  Result<nlohmann::json> sample_frames(const std::string& id, const WorldPoint& min, std::array<int, 3> size,
                                       double step) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace solidtex::server
