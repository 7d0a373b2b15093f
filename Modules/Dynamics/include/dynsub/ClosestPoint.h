#pragma once
// Closest points on the exact limit surface (TVCG §3.2: springs attach to the
// nearest limit-surface point). Candidates come from a k-d tree over a
// tessellation of the limit surface (samplesPerElement^2 points per element);
// each candidate element is then searched by Newton's method in (u, v) on the
// exact surface, kept inside [0,1]^2, and the nearest result wins.
//
// Accuracy: when the tessellation is fine enough that the true closest point
// lies in an element touching one of the `candidates` nearest samples, the
// result is the exact closest point to about 1e-8 of the element size (Newton
// stops on a step below 1e-12 in parameters or after 30 iterations; the
// largest error ClosestPointUnitTest sees on normal and special elements is
// 6e-9 of the element's diagonal).
#include <memory>
#include <vector>

#include "dynsub/LimitSurface.h"

namespace dynsub {

struct ClosestPoint {
  ElementPoint point;
  Vector3 position;  // mm
  double distance = 0;
  Vector3 normal = Vector3::Zero();  // unit limit normal at the point (zero where undefined)
};

// The distance from `query` to the surface point `position`, signed along
// the unit `normal` there (positive on the normal's side); unsigned where
// the normal is undefined (zero).
double signedDistance(const Vector3& query, const Vector3& position, const Vector3& normal);

// Not for concurrent use: searches are const but may rebuild the sample tree
// (each call parallelizes over its queries itself).
class ClosestPointLocator {
 public:
  // The surface must outlive the locator. samplesPerElement in 2..64.
  explicit ClosestPointLocator(const LimitSurface& surface, int samplesPerElement = 6, int candidates = 6);
  ~ClosestPointLocator();
  ClosestPointLocator(ClosestPointLocator&&) noexcept;
  ClosestPointLocator& operator=(ClosestPointLocator&&) noexcept;

  // New control points (#control vertices x 3). The sample tree is rebuilt
  // lazily, by the first search that needs the samples where they are now.
  void update(const MatrixX3& controlPoints);
  ClosestPoint find(const Vector3& query) const;
  // With a hint (e.g. last step's closest point): Newton's method from the hint
  // first, kept if it is at least as near as the nearest tessellation sample
  // (so within the tessellation's accuracy of the true closest point); the full
  // search otherwise. For tracking a moving surface; use find() for errors.
  // While the surface moves little, most of these decisions are made against
  // the tree of an earlier state (see ClosestPoint.cpp) and cost no rebuild;
  // the results are the same as with a tree rebuilt at every update.
  ClosestPoint find(const Vector3& query, const ElementPoint& hint) const;
  // One result per row of `queries`, in order (in parallel; deterministic).
  // Searches may rebuild the tree: calls on one locator must not overlap.
  std::vector<ClosestPoint> findAll(const MatrixX3& queries) const;
  std::vector<ClosestPoint> findAll(const MatrixX3& queries, const std::vector<ElementPoint>& hints) const;
  // The surface's patchOperator(), which update() applies to find points on
  // normal elements without going through the surface's general path.
  const SparseMatrix& patchOperator() const;

 private:
  struct Impl;
  ClosestPoint search(const Vector3& query) const;  // the full search on a current tree
  std::unique_ptr<Impl> impl_;
};

// Distances (mm) from fixed points to a surface that moves and now and then
// is refined, for following a fit as it evolves: the locator is built once
// per level and each call starts from the last call's nearest points
// (ClosestPointLocator::find with hints), so a call costs about one Newton
// search per point instead of a new tessellation and a full search.
class TrackedDistances {
 public:
  explicit TrackedDistances(MatrixX3 points);
  ~TrackedDistances();
  // `level` tells surfaces apart: a level other than the last call's (or a
  // surface of another size) builds a new locator. The surface must live
  // until the next call.
  Eigen::VectorXd measure(const LimitSurface& surface, int level, const MatrixX3& controlPoints);

 private:
  MatrixX3 points_;
  const LimitSurface* surface_ = nullptr;
  int level_ = -1;
  std::unique_ptr<ClosestPointLocator> locator_;
  std::vector<ElementPoint> hints_;
};

}  // namespace dynsub
