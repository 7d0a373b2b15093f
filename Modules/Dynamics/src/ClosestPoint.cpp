#include "dynsub/ClosestPoint.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <thread>

#include <nanoflann.hpp>

#include "dynsub/Error.h"

namespace dynsub {

namespace {

struct SampleCloud {
  Matrix3X points;
  size_t kdtree_get_point_count() const { return static_cast<size_t>(points.rows()); }
  double kdtree_get_pt(size_t i, size_t d) const { return points(static_cast<Eigen::Index>(i), d); }
  template <class Box>
  bool kdtree_get_bbox(Box&) const {
    return false;
  }
};

using Tree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<double, SampleCloud>, SampleCloud, 3>;

// body(i) for i in [0, count): on one contiguous chunk per hardware thread,
// or on this thread alone when there are too few queries to pay for starting
// threads (about 50 us, a few queries' worth). Each query is independent, so
// the results do not depend on the thread count.
// NB: plain threads started per call instead of OpenMP: libgomp's workers
// spin-wait between parallel loops, which took a third of the CPU time of a
// segmentation whose loops are mostly small.
template <class Body>
void parallelFor(Eigen::Index count, const Body& body) {
  constexpr Eigen::Index kSerialBelow = 256;
  const Eigen::Index threads =
      std::min<Eigen::Index>(std::max(1u, std::thread::hardware_concurrency()), count / (kSerialBelow / 2));
  if (count < kSerialBelow || threads < 2) {
    for (Eigen::Index i = 0; i < count; ++i) body(i);
    return;
  }
  std::vector<std::thread> workers;
  const Eigen::Index chunk = (count + threads - 1) / threads;
  for (Eigen::Index t = 1; t < threads; ++t) {
    workers.emplace_back([&, t] {
      for (Eigen::Index i = t * chunk; i < std::min(count, (t + 1) * chunk); ++i) body(i);
    });
  }
  for (Eigen::Index i = 0; i < std::min(count, chunk); ++i) body(i);
  for (std::thread& w : workers) w.join();
}

}  // namespace

struct ClosestPointLocator::Impl {
  const LimitSurface* surface = nullptr;
  int candidates = 6;
  std::vector<ElementPoint> samples;
  SparseMatrix sampleOperator;
  SparseMatrix patchOperator;  // LimitSurface::patchOperator
  std::vector<char> normal;    // per element
  // The k-d tree is built over the samples at the control points of its last
  // build (treeControlPoints) and rebuilt only when a full search needs the
  // samples where they are now. Between builds no sample has moved farther
  // than `drift` mm, so a sample now within r of a point was within r + drift
  // of it in the tree: tracked searches check those few samples where they
  // are now instead of rebuilding the tree at every step.
  SampleCloud cloud;
  std::unique_ptr<Tree> tree;
  Matrix3X treeControlPoints;
  double drift = std::numeric_limits<double>::infinity();
  double sampleWeightBound = 0;  // max over samples of the sum of |weights|
  Matrix3X controlPoints;
  Matrix3X grids;  // patchOperator * controlPoints

  void updateTree() {
    if (drift == 0.0) return;
    cloud.points = sampleOperator * controlPoints;
    tree = std::make_unique<Tree>(3, cloud, nanoflann::KDTreeSingleIndexAdaptorParams(16));
    treeControlPoints = controlPoints;
    drift = 0.0;
  }

  // Whether a tracked closest point at `distance` from q is at least as near
  // as every sample of the surface as it is now.
  bool noSampleNearer(const Vector3& q, double distance) const {
    if (drift == 0.0) {
      uint32_t index = 0;
      double squared = 0.0;
      tree->knnSearch(q.data(), 1, &index, &squared);
      return distance <= std::sqrt(squared);
    }
    const double radius = distance + drift * (1.0 + 1e-9) + 1e-12;  // a margin for rounding
    std::vector<std::pair<uint32_t, double>> within;
    tree->radiusSearch(q.data(), radius * radius, within, nanoflann::SearchParams(32, 0.0, false));
    for (const auto& [index, oldSquared] : within) {
      Vector3 now = Vector3::Zero();  // the sample now, summed as sampleOperator * controlPoints does
      for (SparseMatrix::InnerIterator it(sampleOperator, index); it; ++it)
        now += it.value() * controlPoints.row(it.col()).transpose();
      if (std::sqrt((now - q).squaredNorm()) < distance) return false;
    }
    return true;
  }

  // The limit surface at p: on a normal element from its grid of this state
  // (a 6 x 16 by 16 x 3 product), elsewhere through the surface.
  LimitSample evaluate(const ElementPoint& p) const {
    if (!normal[p.element]) return surface->evaluate(p, controlPoints);
    return limitSampleOf(bicubicBsplineWeights(p.u, p.v) *
                         grids.middleRows<16>(16 * static_cast<Eigen::Index>(p.element)));
  }

  // Newton's method for min |s(u, v) - q|^2 on one element, from (u, v), kept in [0,1]^2.
  ClosestPoint refine(ElementPoint p, const Vector3& q) const {
    if (p.element < 0 || p.element >= static_cast<int>(normal.size()) ||
        !(p.u >= 0.0 && p.u <= 1.0 && p.v >= 0.0 && p.v <= 1.0)) {
      throw Error("internal: closest-point search started outside the surface");
    }
    LimitSample s = evaluate(p);
    double best = (s.position - q).squaredNorm();
    for (int iteration = 0; iteration < 30; ++iteration) {
      const Vector3 r = s.position - q;
      const Eigen::Vector2d gradient(s.du.dot(r), s.dv.dot(r));
      Eigen::Matrix2d hessian;
      hessian << s.du.dot(s.du) + s.duu.dot(r), s.du.dot(s.dv) + s.duv.dot(r), s.du.dot(s.dv) + s.duv.dot(r),
          s.dv.dot(s.dv) + s.dvv.dot(r);
      // Where the full Hessian is not positive definite (far from the surface,
      // near a ridge of the distance), fall back to Gauss-Newton.
      if (!(hessian.determinant() > 0.0 && hessian(0, 0) > 0.0)) {
        hessian << s.du.dot(s.du), s.du.dot(s.dv), s.du.dot(s.dv), s.dv.dot(s.dv);
        hessian.diagonal().array() += 1e-12 * (hessian.trace() + 1e-300);
      }
      Eigen::Vector2d step = -hessian.ldlt().solve(gradient);
      // Coordinates pinned on the border with the gradient pushing outward stay.
      const double uv[2] = {p.u, p.v};
      for (int k = 0; k < 2; ++k) {
        if ((uv[k] <= 0.0 && gradient(k) > 0.0) || (uv[k] >= 1.0 && gradient(k) < 0.0)) step(k) = 0.0;
      }
      if (!step.allFinite() || step.norm() < 1e-12) break;
      bool improved = false;
      for (int halving = 0; halving < 20; ++halving) {
        ElementPoint trial{p.element, std::clamp(p.u + step(0), 0.0, 1.0), std::clamp(p.v + step(1), 0.0, 1.0)};
        const LimitSample t = evaluate(trial);
        const double d = (t.position - q).squaredNorm();
        if (d <= best) {
          improved = (best - d) > 0.0 || std::abs(trial.u - p.u) + std::abs(trial.v - p.v) > 0.0;
          best = d;
          p = trial;
          s = t;
          break;
        }
        step *= 0.5;
      }
      if (!improved) break;
    }
    return ClosestPoint{p, s.position, std::sqrt(best), s.normal};
  }
};

ClosestPointLocator::ClosestPointLocator(const LimitSurface& surface, int samplesPerElement, int candidates)
    : impl_(std::make_unique<Impl>()) {
  if (samplesPerElement < 2 || samplesPerElement > 64) {
    throw Error("closest-point search takes 2..64 samples per element side, got " + std::to_string(samplesPerElement));
  }
  if (candidates < 1 || candidates > 64) throw Error("closest-point candidates must be 1..64");
  impl_->surface = &surface;
  impl_->candidates = candidates;
  // Samples at the centres of a grid of cells, so no two lie on a shared edge.
  for (int e = 0; e < surface.elementCount(); ++e) {
    for (int j = 0; j < samplesPerElement; ++j) {
      for (int i = 0; i < samplesPerElement; ++i) {
        impl_->samples.push_back(
            ElementPoint{e, (i + 0.5) / samplesPerElement, (j + 0.5) / samplesPerElement});
      }
    }
  }
  impl_->sampleOperator = surface.limitOperator(impl_->samples);
  Eigen::VectorXd absoluteRowSums = Eigen::VectorXd::Zero(impl_->sampleOperator.rows());
  for (Eigen::Index c = 0; c < impl_->sampleOperator.outerSize(); ++c)
    for (SparseMatrix::InnerIterator it(impl_->sampleOperator, c); it; ++it) absoluteRowSums(it.row()) += std::abs(it.value());
  impl_->sampleWeightBound = absoluteRowSums.size() ? absoluteRowSums.maxCoeff() : 0.0;
  impl_->patchOperator = surface.patchOperator();
  impl_->normal.resize(surface.elementCount());
  for (int e = 0; e < surface.elementCount(); ++e) impl_->normal[e] = surface.elementType(e) == ElementType::Normal;
}

const SparseMatrix& ClosestPointLocator::patchOperator() const { return impl_->patchOperator; }

ClosestPointLocator::~ClosestPointLocator() = default;
ClosestPointLocator::ClosestPointLocator(ClosestPointLocator&&) noexcept = default;
ClosestPointLocator& ClosestPointLocator::operator=(ClosestPointLocator&&) noexcept = default;

void ClosestPointLocator::update(const Matrix3X& controlPoints) {
  if (controlPoints.rows() != impl_->surface->controlVertexCount()) {
    throw Error("closest-point search got " + std::to_string(controlPoints.rows()) + " control points for " +
                std::to_string(impl_->surface->controlVertexCount()));
  }
  if (!controlPoints.allFinite()) throw Error("closest-point search got non-finite control points");
  Impl& s = *impl_;
  s.controlPoints = controlPoints;
  s.grids = s.patchOperator * controlPoints;
  if (s.tree) {
    // |sample move| <= sum |weights| * largest control-point move.
    const double moved = (controlPoints - s.treeControlPoints).rowwise().norm().maxCoeff();
    s.drift = s.sampleWeightBound * moved;
  }
}

ClosestPoint ClosestPointLocator::find(const Vector3& query) const {
  if (impl_->controlPoints.size() == 0) throw Error("internal: closest-point search used before update()");
  impl_->updateTree();
  return search(query);
}

ClosestPoint ClosestPointLocator::find(const Vector3& query, const ElementPoint& hint) const {
  return findAll(query.transpose(), {hint}).front();
}

// The full search (the tree is current).
ClosestPoint ClosestPointLocator::search(const Vector3& query) const {
  const Impl& s = *impl_;
  if (!query.allFinite()) throw Error("closest-point query is not finite");
  const size_t k = std::min<size_t>(s.candidates, s.samples.size());
  std::vector<uint32_t> index(k);
  std::vector<double> squared(k);
  const size_t found = s.tree->knnSearch(query.data(), k, index.data(), squared.data());
  ClosestPoint best;
  best.distance = std::numeric_limits<double>::infinity();
  std::vector<int> tried;
  for (size_t i = 0; i < found; ++i) {
    const ElementPoint start = s.samples[index[i]];
    if (std::find(tried.begin(), tried.end(), start.element) != tried.end()) continue;
    tried.push_back(start.element);
    const ClosestPoint c = s.refine(start, query);
    if (c.distance < best.distance) best = c;
  }
  return best;
}

std::vector<ClosestPoint> ClosestPointLocator::findAll(const Matrix3X& queries) const {
  if (impl_->controlPoints.size() == 0) throw Error("internal: closest-point search used before update()");
  impl_->updateTree();
  std::vector<ClosestPoint> result(queries.rows());
  parallelFor(queries.rows(), [&](Eigen::Index i) { result[i] = search(queries.row(i).transpose()); });
  return result;
}

std::vector<ClosestPoint> ClosestPointLocator::findAll(const Matrix3X& queries,
                                                       const std::vector<ElementPoint>& hints) const {
  Impl& s = *impl_;
  if (s.controlPoints.size() == 0) throw Error("internal: closest-point search used before update()");
  if (hints.size() != static_cast<size_t>(queries.rows())) throw Error("internal: one hint per query expected");
  if (!queries.allFinite()) throw Error("closest-point query is not finite");
  if (!s.tree) s.updateTree();
  // A tracked point is kept when it is at least as near as the nearest
  // sample (see Impl::noSampleNearer); the rest get the full search on a
  // current tree.
  std::vector<ClosestPoint> result(queries.rows());
  std::vector<char> decided(queries.rows(), 0);
  parallelFor(queries.rows(), [&](Eigen::Index i) {
    const ElementPoint& hint = hints[i];
    if (hint.element < 0 || hint.element >= s.surface->elementCount()) return;
    const Vector3 q = queries.row(i).transpose();
    result[i] = s.refine(hint, q);
    decided[i] = s.noSampleNearer(q, result[i].distance);
  });
  if (std::find(decided.begin(), decided.end(), 0) == decided.end()) return result;
  s.updateTree();
  parallelFor(queries.rows(), [&](Eigen::Index i) {
    if (decided[i]) return;
    const Vector3 q = queries.row(i).transpose();
    const ElementPoint& hint = hints[i];
    if (hint.element < 0 || hint.element >= s.surface->elementCount()) {
      result[i] = search(q);
      return;
    }
    const ClosestPoint searched = search(q);
    if (searched.distance < result[i].distance) result[i] = searched;
  });
  return result;
}

TrackedDistances::TrackedDistances(Matrix3X points) : points_(std::move(points)) {}
TrackedDistances::~TrackedDistances() = default;

Eigen::VectorXd TrackedDistances::measure(const LimitSurface& surface, int level, const Matrix3X& controlPoints) {
  if (&surface != surface_ || level != level_ || !locator_) {
    locator_ = std::make_unique<ClosestPointLocator>(surface);
    surface_ = &surface;
    level_ = level;
    hints_.clear();
  }
  locator_->update(controlPoints);
  const std::vector<ClosestPoint> nearest =
      hints_.empty() ? locator_->findAll(points_) : locator_->findAll(points_, hints_);
  hints_.resize(nearest.size());
  Eigen::VectorXd distances(static_cast<Eigen::Index>(nearest.size()));
  for (size_t i = 0; i < nearest.size(); ++i) {
    hints_[i] = nearest[i].point;
    distances(static_cast<Eigen::Index>(i)) = nearest[i].distance;
  }
  return distances;
}

}  // namespace dynsub
