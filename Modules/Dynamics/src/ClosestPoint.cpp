#include "dynsub/ClosestPoint.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <string>

#include <nanoflann.hpp>

#include "dynsub/ParallelFor.h"
#include "dynsub/ApplyOperator.h"
#include "dynsub/Error.h"

namespace dynsub {

namespace {

struct SampleCloud {
  MatrixX3 points;
  size_t kdtree_get_point_count() const { return static_cast<size_t>(points.rows()); }
  double kdtree_get_pt(size_t i, size_t d) const { return points(static_cast<Eigen::Index>(i), d); }
  template <class Box>
  bool kdtree_get_bbox(Box&) const {
    return false;
  }
};

using Tree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<double, SampleCloud>, SampleCloud, 3>;

}  // namespace

struct ClosestPointLocator::Impl {
  const LimitSurface* surface = nullptr;
  int candidates = 6;
  // Samples: samplesPerSide^2 per element, element by element. On a normal
  // element a sample is gridWeights.row(local) times the element's grid (the
  // same parameters on every element); elsewhere a row of specialOperator.
  std::vector<ElementPoint> samples;
  int perElement = 0;  // samples per element
  Eigen::Matrix<double, Eigen::Dynamic, 16> gridWeights;
  SparseMatrix specialOperator;
  std::vector<int> specialRow;  // per sample: its row of specialOperator, -1 on normal elements
  std::vector<char> normal;  // per element
  SampleCloud cloud;
  std::unique_ptr<Tree> tree;
  MatrixX3 treeControlPoints;
  double drift = std::numeric_limits<double>::infinity();
  double sampleWeightBound = 0;  // max over samples of the sum of |weights|
  MatrixX3 controlPoints;
  // specialOperator * controlPoints.
  // Computed at every update: the checks for a nearer sample read the
  // special elements' samples many times over, and a sparse row each time
  // would cost far more.
  MatrixX3 specialSamples;
  // The surface at controlPoints: the normal elements' grids (its
  // patchOperator times them) and the special elements' pieces.
  std::unique_ptr<SurfaceState> state;

  // Where sample i lies at the current control points.
  Vector3 sample(Eigen::Index i) const {
    const int row = specialRow[i];
    if (row >= 0) return specialSamples.row(row).transpose();
    const Eigen::Index element = i / perElement;
    return (gridWeights.row(i % perElement) * state->grids().middleRows<16>(16 * element)).transpose();
  }

  void updateTree() {
    if (drift == 0.0) return;
    cloud.points.resize(static_cast<Eigen::Index>(samples.size()), 3);
    for (Eigen::Index e = 0; e < static_cast<Eigen::Index>(normal.size()); ++e) {
      auto block = cloud.points.middleRows(e * perElement, perElement);
      if (normal[e]) {
        block.noalias() = gridWeights * state->grids().middleRows<16>(16 * e);
      } else {
        block = specialSamples.middleRows(specialRow[e * perElement], perElement);
      }
    }
    // 64 samples a leaf, not nanoflann's usual 10-16: the tree is rebuilt
    // at most evaluations of a fit and queried only a few times per rebuild,
    // so its build time counts most; larger leaves build faster and do not
    // slow these searches.
    tree = std::make_unique<Tree>(3, cloud, nanoflann::KDTreeSingleIndexAdaptorParams(64));
    treeControlPoints = controlPoints;
    drift = 0.0;
  }

  // Whether a sample of the surface as it is now lies nearer to q than a
  // tracked closest point at `distance`. Unknown when too many samples of the
  // tree are candidates (a point far off the surface): a current tree is then
  // cheaper than checking them one by one.
  // `mostChecked` bounds the samples checked one by one (64 by default;
  // findAll allows more for the few queries it decides on an old tree).
  enum class Nearer { No, Yes, Unknown };
  static constexpr std::size_t kMostChecked = 64;
  Nearer sampleNearer(const Vector3& q, double distance, std::size_t mostChecked = kMostChecked) const {
    if (drift == 0.0) {
      uint32_t index = 0;
      double squared = 0.0;
      tree->knnSearch(q.data(), 1, &index, &squared);
      return distance <= std::sqrt(squared) ? Nearer::No : Nearer::Yes;
    }
    const double radius = driftRadius(distance);
    NearerSampleSearch search{*this, q, distance, radius * radius, mostChecked};
    tree->findNeighbors(search, q.data(), nanoflann::SearchParams(32, 0.0, false));
    return search.answer;
  }

  // The radius on the tree (its samples where they were when it was built)
  // that holds every sample within `distance` of a point now.
  // (1e-9 and 1e-12: a margin for rounding.)
  double driftRadius(double distance) const { return distance + drift * (1.0 + 1e-9) + 1e-12; }

  // A nanoflann result set for sampleNearer: each sample of the old tree
  // within `radius` of q is checked where it is now, and the search stops at
  // the first one nearer than `distance` (Yes) or when over `mostChecked`
  // are within the radius (Unknown). No list of neighbours is kept.
  // The ball usually holds a sample or two, so stopping at the first
  // nearer one is cheaper than a search for the 65 nearest, and keeping no
  // list saves a radius search's time growing one.
  struct NearerSampleSearch {
    using DistanceType = double;
    using IndexType = uint32_t;
    const Impl& impl;
    const Vector3& q;
    double distance;
    double squaredRadius;
    std::size_t mostChecked;
    std::size_t checked = 0;
    Nearer answer = Nearer::No;

    bool full() const { return true; }
    double worstDist() const { return squaredRadius; }
    bool addPoint(double squared, uint32_t index) {
      if (!(squared < squaredRadius)) return true;
      if (++checked > mostChecked) {
        answer = Nearer::Unknown;
        return false;
      }
      if (std::sqrt((impl.sample(index) - q).squaredNorm()) < distance) {
        answer = Nearer::Yes;
        return false;
      }
      return true;
    }
  };

  // The samples within `radius` of q on the tree (at the positions it was
  // built with), at most kMostInBall of them: `overflow` when there are more.
  // kMostInBall also bounds sampleNearer's checks for findAll's few queries
  // decided on an old tree.
  static constexpr std::size_t kMostInBall = 1024;
  struct BallSearch {
    using DistanceType = double;
    using IndexType = uint32_t;
    double squaredRadius;
    std::vector<uint32_t>& found;
    bool overflow = false;

    bool full() const { return true; }
    double worstDist() const { return squaredRadius; }
    bool addPoint(double squared, uint32_t index) {
      if (!(squared < squaredRadius)) return true;
      if (found.size() >= kMostInBall) {
        overflow = true;
        return false;
      }
      found.push_back(index);
      return true;
    }
  };
  bool ball(const Vector3& q, double radius, std::vector<uint32_t>& found) const {
    found.clear();
    BallSearch search{radius * radius, found};
    tree->findNeighbors(search, q.data(), nanoflann::SearchParams(32, 0.0, false));
    return !search.overflow;
  }

  // The `candidates` samples nearest q where they are now, nearest first
  // (ties by index), found on a tree older than the surface: the k nearest
  // of the tree bound the k-th nearest distance now, D, and no sample
  // farther than D + drift on the tree is within D now. False when that
  // ball holds over kMostInBall samples.
  bool nearestSamplesOnOldTree(const Vector3& q, std::vector<uint32_t>& nearest) const {
    const size_t k = std::min<size_t>(candidates, samples.size());
    std::vector<uint32_t> index(k);
    std::vector<double> squared(k);
    const size_t found = tree->knnSearch(q.data(), k, index.data(), squared.data());
    double bound = 0.0;
    for (size_t i = 0; i < found; ++i) bound = std::max(bound, std::sqrt((sample(index[i]) - q).squaredNorm()));
    std::vector<uint32_t> inBall;
    if (!ball(q, driftRadius(bound), inBall)) return false;
    std::vector<std::pair<double, uint32_t>> now;
    for (uint32_t i : inBall) now.emplace_back((sample(i) - q).squaredNorm(), i);
    const size_t kept = std::min(k, now.size());
    std::partial_sort(now.begin(), now.begin() + static_cast<long>(kept), now.end());
    nearest.clear();
    for (size_t i = 0; i < kept; ++i) nearest.push_back(now[i].second);
    return true;
  }

  // Newton's method from each of the nearest samples' elements (the first
  // sample of each), the nearest result: the full search's second half.
  ClosestPoint refineFrom(const std::vector<uint32_t>& nearest, const Vector3& q) const {
    ClosestPoint best;
    best.distance = std::numeric_limits<double>::infinity();
    std::vector<int> tried;
    for (uint32_t i : nearest) {
      const ElementPoint start = samples[i];
      if (std::find(tried.begin(), tried.end(), start.element) != tried.end()) continue;
      tried.push_back(start.element);
      const ClosestPoint c = refine(start, q);
      if (c.distance < best.distance) best = c;
    }
    return best;
  }

  // Whether p names a point of the surface: an element, with (u, v) in [0,1]^2.
  bool onSurface(const ElementPoint& p) const {
    return p.element >= 0 && p.element < static_cast<int>(normal.size()) && p.u >= 0.0 && p.u <= 1.0 &&
           p.v >= 0.0 && p.v <= 1.0;
  }

  // Newton's method for min |s(u, v) - q|^2 on one element, from (u, v), kept in [0,1]^2.
  static constexpr double kShortStep = 1e-6;  // in element parameters
  ClosestPoint refine(ElementPoint p, const Vector3& q) const {
    if (!onSurface(p)) throw Error("internal: closest-point search started outside the surface");
    LimitSample s = state->evaluate(p);
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
      // Near the minimum Newton converges quadratically, so a short full
      // step that does not improve means the distance is at its rounding
      // floor; halving it 20 times more (an evaluation each) would be most of
      // a search's evaluations, for nothing.
      const int halvings = step.norm() < kShortStep ? 1 : 20;
      for (int halving = 0; halving < halvings; ++halving) {
        ElementPoint trial{p.element, std::clamp(p.u + step(0), 0.0, 1.0), std::clamp(p.v + step(1), 0.0, 1.0)};
        const LimitSample t = state->evaluate(trial);
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
  impl_->state = std::make_unique<SurfaceState>(surface);
  // Samples at the centres of a grid of cells, so no two lie on a shared edge.
  for (int e = 0; e < surface.elementCount(); ++e) {
    for (int j = 0; j < samplesPerElement; ++j) {
      for (int i = 0; i < samplesPerElement; ++i) {
        impl_->samples.push_back(
            ElementPoint{e, (i + 0.5) / samplesPerElement, (j + 0.5) / samplesPerElement});
      }
    }
  }
  impl_->perElement = samplesPerElement * samplesPerElement;
  impl_->gridWeights.resize(impl_->perElement, 16);
  for (int i = 0; i < impl_->perElement; ++i)
    impl_->gridWeights.row(i) = bicubicBsplineWeights(impl_->samples[i].u, impl_->samples[i].v).row(0);
  impl_->normal.resize(surface.elementCount());
  std::vector<ElementPoint> special;
  impl_->specialRow.assign(impl_->samples.size(), -1);
  for (int e = 0; e < surface.elementCount(); ++e) {
    impl_->normal[e] = surface.elementType(e) == ElementType::Normal;
    if (impl_->normal[e]) continue;
    for (int i = 0; i < impl_->perElement; ++i) {
      impl_->specialRow[e * impl_->perElement + i] = static_cast<int>(special.size());
      special.push_back(impl_->samples[e * impl_->perElement + i]);
    }
  }
  impl_->specialOperator = surface.limitOperator(special);
  // A sample moves at most (sum of its |weights|) x the largest control-point
  // move. On normal elements the bicubic weights are >= 0 and sum to 1, so
  // the grid rows' sums bound them.
  double bound = 0.0;
  const SparseMatrix* operators[] = {&impl_->specialOperator, &impl_->state->patchOperator()};
  for (const SparseMatrix* m : operators)
    for (Eigen::Index r = 0; r < m->outerSize(); ++r) {
      double sum = 0.0;
      for (SparseMatrix::InnerIterator it(*m, r); it; ++it) sum += std::abs(it.value());
      bound = std::max(bound, sum);
    }
  impl_->sampleWeightBound = bound;
}

const SparseMatrix& ClosestPointLocator::patchOperator() const { return impl_->state->patchOperator(); }

ClosestPointLocator::~ClosestPointLocator() = default;
ClosestPointLocator::ClosestPointLocator(ClosestPointLocator&&) noexcept = default;
ClosestPointLocator& ClosestPointLocator::operator=(ClosestPointLocator&&) noexcept = default;

void ClosestPointLocator::update(const MatrixX3& controlPoints) {
  if (controlPoints.rows() != impl_->surface->controlVertexCount()) {
    throw Error("closest-point search got " + std::to_string(controlPoints.rows()) + " control points for " +
                std::to_string(impl_->surface->controlVertexCount()));
  }
  if (!controlPoints.allFinite()) throw Error("closest-point search got non-finite control points");
  Impl& s = *impl_;
  s.controlPoints = controlPoints;
  s.state->reset(controlPoints);
  applyOperator(s.specialOperator, controlPoints, s.specialSamples);
  if (s.tree) {
    // |sample move| <= sum |weights| * largest control-point move.
    const double moved = (controlPoints - s.treeControlPoints).rowwise().norm().maxCoeff();
    s.drift = s.sampleWeightBound * moved;
  }
}

double signedDistance(const Vector3& query, const Vector3& position, const Vector3& normal) {
  return normal.isZero(0.0) ? (query - position).norm() : normal.dot(query - position);
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
  index.resize(found);
  return s.refineFrom(index, query);
}

std::vector<ClosestPoint> ClosestPointLocator::findAll(const MatrixX3& queries) const {
  if (impl_->controlPoints.size() == 0) throw Error("internal: closest-point search used before update()");
  if (!queries.allFinite()) throw Error("closest-point query is not finite");  // before the workers start
  impl_->updateTree();
  std::vector<ClosestPoint> result(queries.rows());
  parallelFor(queries.rows(), threadsWorth(queries.rows()),
              [&](Eigen::Index i) { result[i] = search(queries.row(i).transpose()); });
  return result;
}

std::vector<ClosestPoint> ClosestPointLocator::findAll(const MatrixX3& queries,
                                                       const std::vector<ElementPoint>& hints) const {
  Impl& s = *impl_;
  if (s.controlPoints.size() == 0) throw Error("internal: closest-point search used before update()");
  if (hints.size() != static_cast<size_t>(queries.rows())) throw Error("internal: one hint per query expected");
  if (!queries.allFinite()) throw Error("closest-point query is not finite");
  if (!s.tree) s.updateTree();
  // A tracked point is kept when no sample is nearer (Impl::sampleNearer).
  // The checks are made on the tree as it was built, for the samples within
  // the drift. The few queries they leave undecided are decided on that old
  // tree too, exactly (sampleNearer checking up to the share of samples
  // below, and a full search of the samples nearest now where one is
  // nearer); when there are more than kMostUndecided, or that share is under
  // kMostChecked, or a hint is off the surface, or a ball is too full, the
  // tree is rebuilt and every query is decided on the
  // current one.
  // Early in a fit, while the surface moves fast, most queries come out
  // Unknown (over 64 samples in the ball of the drift): past kMostUndecided
  // the checks stop, as a current tree is cheaper. Late in it only a handful
  // per evaluation are undecided, and deciding them on the old tree saves a
  // rebuild at nearly every evaluation. Every decision depends on the
  // queries alone, not on which thread made it.
  constexpr Eigen::Index kMostUndecided = 64;
  std::vector<ClosestPoint> result(queries.rows());
  std::vector<char> undecided(queries.rows(), 0);
  std::atomic<Eigen::Index> undecidedCount{0};
  std::atomic<bool> rebuild{false};
  parallelFor(queries.rows(), threadsWorth(queries.rows()), [&](Eigen::Index i) {
    const ElementPoint& hint = hints[i];
    if (!s.onSurface(hint)) {  // a hint off the surface (another level's) means a full search, below
      rebuild = true;
      return;
    }
    const Vector3 q = queries.row(i).transpose();
    result[i] = s.refine(hint, q);
    if (rebuild.load(std::memory_order_relaxed)) return;
    if (s.sampleNearer(q, result[i].distance) != Impl::Nearer::No) {
      undecided[i] = 1;
      if (++undecidedCount > kMostUndecided) rebuild = true;
    }
  });
  if (!rebuild && undecidedCount == 0) return result;
  // The old tree's decisions check at most a quarter of the tree's samples
  // in all, shared out among the undecided queries; a rebuild evaluates
  // every sample and sorts them again.
  // Without this bound a few queries whose balls hold hundreds of
  // samples (a segmentation's landmarks while the surface moves fast) would
  // check more samples than a rebuild evaluates.
  const std::size_t undecidedQueries = static_cast<std::size_t>(std::max<Eigen::Index>(1, undecidedCount));
  const std::size_t mostChecked = std::min(Impl::kMostInBall, s.samples.size() / 4 / undecidedQueries);
  if (!rebuild && s.drift > 0.0 && mostChecked >= Impl::kMostChecked) {
    std::vector<Eigen::Index> open;
    for (Eigen::Index i = 0; i < queries.rows(); ++i)
      if (undecided[i]) open.push_back(i);
    std::vector<ClosestPoint> decided(open.size());
    std::atomic<bool> full{false};  // once one query needs the current tree, the others' checks are moot
    parallelFor(static_cast<Eigen::Index>(open.size()), static_cast<Eigen::Index>(open.size()) / 16,
                [&](Eigen::Index t) {
                  if (full.load(std::memory_order_relaxed)) return;
                  const Eigen::Index i = open[t];
                  const Vector3 q = queries.row(i).transpose();
                  decided[t] = result[i];
                  const Impl::Nearer nearer = s.sampleNearer(q, result[i].distance, mostChecked);
                  if (nearer == Impl::Nearer::No) return;
                  std::vector<uint32_t> nearest;
                  if (nearer == Impl::Nearer::Unknown || !s.nearestSamplesOnOldTree(q, nearest)) {
                    full = true;
                    return;
                  }
                  const ClosestPoint searched = s.refineFrom(nearest, q);
                  if (searched.distance < decided[t].distance) decided[t] = searched;
                });
    if (!full) {
      for (size_t t = 0; t < open.size(); ++t) result[open[t]] = decided[t];
      return result;
    }
  }
  s.updateTree();
  parallelFor(queries.rows(), threadsWorth(queries.rows()), [&](Eigen::Index i) {
    const Vector3 q = queries.row(i).transpose();
    if (!s.onSurface(hints[i])) {
      result[i] = search(q);
      return;
    }
    if (s.sampleNearer(q, result[i].distance) == Impl::Nearer::No) return;  // exact on the current tree
    const ClosestPoint searched = search(q);
    if (searched.distance < result[i].distance) result[i] = searched;
  });
  return result;
}

TrackedDistances::TrackedDistances(MatrixX3 points) : points_(std::move(points)) {}
TrackedDistances::~TrackedDistances() = default;

Eigen::VectorXd TrackedDistances::measure(const LimitSurface& surface, int level, const MatrixX3& controlPoints) {
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
