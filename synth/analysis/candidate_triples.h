// Candidate coordinate triples of one pyramid level (Zhang §2; Dong et al. 2008).
//
// For every pixel p of every plane's exemplar we keep up to N_T triples T with T[plane] = p
// whose three N x N neighborhoods agree along their pairwise crossbars. Plane k's second
// axis is plane k+1's first axis (types.h), so the three crossbars of T are
//   second-axis line of plane k at T[k]  vs  first-axis line of plane k+1 at T[k+1],  k = 0,1,2,
// each N samples at the level's spacing h. Search: the k-NN (FLANN) of p's second-axis line among
// plane k+1's first-axis lines, and of p's first-axis line among plane k+2's second-axis lines;
// every pair (q, r) of those neighbours forms a triple, scored by the sum of all three crossbar
// squared differences. Of the best 2*N_T, triples that are *spatially coherent* with a
// neighbouring pixel (the neighbour at p + h*delta holds T shifted by the same 3D step, Eq. 4)
// are kept first, then the rest by error; the stored list is sorted by error, best first.
//
// When one image serves all three planes the problem is symmetric under cyclic rotation of the
// planes, so only plane xy is searched and planes yz, zx are its rotations (exactly equal to
// searching them). When a plane's image is another's transposed (the crossed layout: E, E^T,
// E^T; analysis.cpp says why the grain layouts do not use it), its first-axis lines are that image's second-axis lines, so
// the planes share line sets, k-NN indices and whole searches: a layout of E and E^T needs
// 2 indices and 4 searches of every pixel instead of 6 and 6. Deterministic: fixed seeds,
// per-pixel work written to fixed slots.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "core/image.h"
#include "core/interrupter.h"
#include "analysis/knn_index.h"
#include "core/status.h"
#include "core/types.h"

namespace solidtex {

struct CandidateParams {
  int neighborhood = 9;   // N, odd, exemplar pixels per crossbar (at the level's spacing)
  int candidates = 12;    // N_T, triples kept per pixel, [1, 64]
  int search_k = 24;      // nearest crossbar lines kept per search; pairs = search_k^2
  KnnParams knn;
};

// A stored triple: its six coordinates as 16-bit exemplar pixels (stored coordinates lie in
// their exemplar, at most 65535 pixels per side), half a CoordinateTriple, so that a pixel's
// 12 candidates span 2.25 cache lines instead of 4.5. Plane k's pair is c[2k], c[2k+1].
struct PackedTriple {
  std::array<uint16_t, 6> c{};
  static constexpr int kMaxSide = 65535;
  // Requires every coordinate in [0, kMaxSide] (compute_level_candidates checks the images).
  static PackedTriple pack(const CoordinateTriple& t) {
    PackedTriple p;
    for (int k = 0; k < 3; ++k) {
      p.c[size_t(2 * k)] = uint16_t(t.at[size_t(k)].x);
      p.c[size_t(2 * k + 1)] = uint16_t(t.at[size_t(k)].y);
    }
    return p;
  }
  // Stored plane k's pixel (before any rotation).
  ExemplarPixel stored(int k) const { return {int32_t(c[size_t(2 * k)]), int32_t(c[size_t(2 * k + 1)])}; }
  // The triple with its planes rotated by r (rotate_planes): out[j] = stored[j - r].
  CoordinateTriple unpack(int r) const {
    CoordinateTriple t;
    for (int j = 0; j < 3; ++j) t.at[size_t(j)] = stored((j - r + 3) % 3);
    return t;
  }
  friend bool operator==(const PackedTriple&, const PackedTriple&) = default;
};

// One pixel's candidates, read as CoordinateTriples (by value) in their plane order.
class CandidateList {
 public:
  class iterator {
   public:
    using value_type = CoordinateTriple;
    using difference_type = std::ptrdiff_t;
    iterator() = default;
    iterator(const PackedTriple* p, int r) : p_(p), r_(r) {}
    CoordinateTriple operator*() const { return p_->unpack(r_); }
    iterator& operator++() { ++p_; return *this; }
    iterator operator++(int) { iterator old = *this; ++p_; return old; }
    friend bool operator==(const iterator& a, const iterator& b) { return a.p_ == b.p_; }
   private:
    const PackedTriple* p_ = nullptr;
    int r_ = 0;
  };
  CandidateList(std::span<const PackedTriple> packed, int rotation) : packed_(packed), rotation_(rotation) {}
  size_t size() const { return packed_.size(); }
  bool empty() const { return packed_.empty(); }
  CoordinateTriple operator[](size_t i) const { return packed_[i].unpack(rotation_); }
  iterator begin() const { return {packed_.data(), rotation_}; }
  iterator end() const { return {packed_.data() + packed_.size(), rotation_}; }
  // The stored triples and the rotation they are read with: plane j of triple i is
  // packed()[i].stored(stored_plane(j)), for hot loops that read single planes.
  std::span<const PackedTriple> packed() const { return packed_; }
  int stored_plane(int j) const { return (j - rotation_ + 3) % 3; }
  int rotation() const { return rotation_; }

 private:
  std::span<const PackedTriple> packed_;
  int rotation_ = 0;
};

// Triples of one plane at one level; slot (y*width + x)*per_pixel + i. Immutable once made
// and cheap to copy: the lists are shared, so a shared exemplar's planes yz and zx are plane
// xy's lists read with their planes rotated (rotation 1 and 2), a third of the memory.
struct PlaneCandidates {
  int width = 0;
  int height = 0;
  int per_pixel = 0;
  int rotation = 0;  // stored triples are read through rotate_planes(t, rotation)
  std::shared_ptr<const std::vector<PackedTriple>> triples;  // width*height*per_pixel slots
  std::shared_ptr<const std::vector<uint8_t>> counts;        // valid triples per pixel, <= per_pixel

  static PlaneCandidates make(int width, int height, int per_pixel, std::vector<PackedTriple> triples,
                              std::vector<uint8_t> counts) {
    PlaneCandidates pc;
    pc.width = width;
    pc.height = height;
    pc.per_pixel = per_pixel;
    pc.triples = std::make_shared<const std::vector<PackedTriple>>(std::move(triples));
    pc.counts = std::make_shared<const std::vector<uint8_t>>(std::move(counts));
    return pc;
  }
  // The same lists read with their planes rotated by k more (sharing the storage).
  PlaneCandidates rotated(int k) const {
    PlaneCandidates pc = *this;
    pc.rotation = (rotation + k) % 3;
    return pc;
  }
  CandidateList at(ExemplarPixel p) const {
    const size_t i = size_t(ImageF::wrap(p.y, height)) * width + ImageF::wrap(p.x, width);
    return {std::span<const PackedTriple>(triples->data() + i * per_pixel, (*counts)[i]), rotation};
  }
  // Equal lists as read (the triples each pixel offers), however they are stored.
  friend bool operator==(const PlaneCandidates& a, const PlaneCandidates& b) {
    if (a.width != b.width || a.height != b.height || a.per_pixel != b.per_pixel) return false;
    if (!a.counts || !b.counts) return !a.counts && !b.counts;
    if (*a.counts != *b.counts) return false;
    for (int y = 0; y < a.height; ++y)
      for (int x = 0; x < a.width; ++x) {
        const CandidateList la = a.at({x, y}), lb = b.at({x, y});
        for (size_t i = 0; i < la.size(); ++i)
          if (la[i] != lb[i]) return false;
      }
    return true;
  }
};

struct LevelCandidates {
  std::array<PlaneCandidates, 3> planes;
  double mean_crossbar_error = 0;    // mean over stored triples (per sample and channel)
  double random_crossbar_error = 0;  // the same measure over uniformly random triples
  double coherent_fraction = 0;      // stored triples coherent with a neighbouring pixel
};

using PlaneStacks = std::array<const ImageF*, 3>;  // one matching image per plane, same channels

// Where a plane's crossbar lines come from: plane `base`'s image (base <= the plane's index),
// transposed or not. {0,F},{0,F},{0,F} is one shared image; {0,F},{1,F},{2,F} three images.
struct PlaneSource {
  int base = 0;
  bool transposed = false;
  friend bool operator==(const PlaneSource&, const PlaneSource&) = default;
};
using PlaneLayout = std::array<PlaneSource, 3>;
inline constexpr PlaneLayout kSharedLayout{{{0, false}, {0, false}, {0, false}}};
inline constexpr PlaneLayout kDistinctLayout{{{0, false}, {1, false}, {2, false}}};
inline constexpr PlaneLayout kCrossedLayout{{{0, false}, {0, true}, {0, true}}};  // xy = E, yz = zx = E^T
// The layout of three exemplar images: a plane equal to plane 0's image, pixel for pixel, or to
// its transpose, shares plane 0's lines; any other plane has its own. Planes 1 and 2 equal to
// each other but unrelated to plane 0 keep their own lines (rare: no layout makes them).
PlaneLayout plane_layout(const std::array<const ImageF*, 3>& images);

// Mean squared difference per crossbar sample and channel.
double crossbar_error(const PlaneStacks& stacks, const CoordinateTriple& t, int n, int spacing);

// Maps plane-xy candidates of a shared exemplar to plane `k`: out[j] = t[j - k].
CoordinateTriple rotate_planes(const CoordinateTriple& t, int k);

// The crossbar lines of one level's distinct images and their k-NN indices: the serial part of
// a level's candidate search (FLANN builds one index at a time, under a process-wide lock), kept
// apart so analysis can prepare the next level while this one searches on every thread.
// Immutable once prepared; searching it is thread-safe. `stacks` must outlive it.
struct CrossbarSearch {
  struct Lines {
    int width = 0, height = 0, dims = 0;
    std::vector<float> first, second;  // row i: pixel i's first- and second-axis line
  };
  PlaneStacks stacks{};
  PlaneLayout layout = kDistinctLayout;
  bool shared() const { return layout == kSharedLayout; }
  int spacing = 1;
  std::array<Lines, 3> lines;           // per base image (index = base; others empty)
  std::array<std::optional<KnnIndex>, 3> first_index;   // per base image: its first-axis lines
  std::array<std::optional<KnnIndex>, 3> second_index;  // per base image: its second-axis lines
};

// The lines of a base plane are built from stacks[base]; a transposed plane's from its base's.
Result<CrossbarSearch> prepare_crossbar_search(const PlaneStacks& stacks, const PlaneLayout& layout, int spacing,
                                               const CandidateParams& params, uint32_t seed);

// `progress(done_fraction)` is called from worker threads; returning true cancels.
Result<LevelCandidates> compute_level_candidates(const CrossbarSearch& search, const CandidateParams& params,
                                                 const std::function<bool(double)>& progress);
// The same, preparing the search first.
Result<LevelCandidates> compute_level_candidates(const PlaneStacks& stacks, const PlaneLayout& layout, int spacing,
                                                 const CandidateParams& params, uint32_t seed,
                                                 const std::function<bool(double)>& progress);
// `shared`: kSharedLayout, else kDistinctLayout.
Result<LevelCandidates> compute_level_candidates(const PlaneStacks& stacks, bool shared, int spacing,
                                                 const CandidateParams& params, uint32_t seed,
                                                 const std::function<bool(double)>& progress);

// Fills mean/random error and coherent fraction of `level` (used after loading a table, too).
void measure_level_candidates(const PlaneStacks& stacks, int n, int spacing, uint32_t seed,
                              LevelCandidates& level);

}  // namespace solidtex
