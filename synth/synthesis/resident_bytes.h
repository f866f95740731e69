// Resident memory of what a loaded volume keeps between requests, outside its voxel cache
// (issue 11): candidate-triple tables, frame fields and a synthesizer's own state (per-level
// correction constants, stencils, schedules). Counted from the containers' sizes, so the
// numbers are what the objects hold (within allocator rounding), not guesses; the service sums
// them to bound loaded volumes (--volume-state-mb). Surface-distance bands count themselves
// (SurfaceDistance::resident_bytes). Thread-safe: pure functions of immutable objects.
#pragma once

#include <cstdint>

#include "analysis/table.h"
#include "field/frame_field.h"
#include "synthesis/synthesizer.h"

namespace solidtex {

// Stacks, appearance vectors, PCA bases, candidate triples and exemplar images (each shared
// image or plane counted once).
int64_t table_resident_bytes(const Table& table);

// A quaternion grid's nodes and log scales (an upper bound: scales counted whether present or
// not); a constant field's object.
int64_t field_resident_bytes(const FrameField& field);

// The synthesizer's own state: per-level correction contexts (PCA projections), constant-field
// stencils and offsets, schedules. Not its table, field or cache (counted apart).
int64_t synthesizer_state_bytes(const Synthesizer& synthesizer);

}  // namespace solidtex
