#include "dynsub/SolidDynamics.h"

#include <cmath>

#include <Eigen/SparseCholesky>

#include "dynsub/Coordinates.h"
#include "dynsub/Error.h"

namespace dynsub {

struct SolidModel::Springs {
  std::vector<std::array<int, 2>> normal;  // mass points
  std::vector<double> normalRest;
  std::vector<std::array<int, 3>> virtuals;  // (corner m, neighbours a, b): m to (a + b) / 2
  std::vector<double> virtualRest;
};

struct SolidModel::Solver {
  std::vector<int> freeIndex;  // control point -> free row, or -1
  SparseMatrix A1;             // #data x #free
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt;  // of m A1^T A1
};

SolidModel::SolidModel(const Lattice& control, int levels, const SolidMaterial& material)
    : control_(control), p_(control.points()), v_(MatrixX3::Zero(control.pointCount(), 3)),
      fixed_(control.pointCount(), false), springs_(std::make_unique<Springs>()) {
  if (levels < 0 || levels > 4) throw Error("the solid's subdivision level must be 0 to 4 (got " + std::to_string(levels) + ")");
  refined_ = subdivideSolid(control, levels);
  for (const auto& e : refined_.lattice.edges()) springs_->normal.push_back(e);
  for (const auto& loop : refined_.lattice.faces()) {
    const int n = static_cast<int>(loop.size());
    for (int i = 0; i < n; ++i) springs_->virtuals.push_back({loop[i], loop[(i + n - 1) % n], loop[(i + 1) % n]});
  }
  setMaterial(material);
  resetRestLengths();
}

SolidModel::~SolidModel() = default;

MatrixX3 SolidModel::dataPoints() const { return refined_.A * p_; }
int SolidModel::springCount() const { return static_cast<int>(springs_->normal.size()); }
int SolidModel::virtualSpringCount() const { return static_cast<int>(springs_->virtuals.size()); }

void SolidModel::setControlPoints(const MatrixX3& points) {
  if (points.rows() != p_.rows() || !points.allFinite())
    throw Error("the solid needs " + std::to_string(p_.rows()) + " finite control points (got " +
                std::to_string(points.rows()) + ")");
  p_ = points;
  v_.setZero();
}

void SolidModel::setMaterial(const SolidMaterial& material) {
  for (double value : {material.mass, material.springStiffness, material.virtualStiffness})
    if (!(std::isfinite(value) && value > 0)) throw Error("the solid's mass and stiffnesses must be finite and > 0");
  if (!(std::isfinite(material.damping) && material.damping >= 0)) throw Error("the solid's damping must be >= 0");
  const bool massChanged = !solver_ || material.mass != material_.mass;
  material_ = material;
  if (massChanged) factor();
}

void SolidModel::fix(const std::vector<int>& points) {
  for (int i : points) {
    if (i < 0 || i >= control_.pointCount()) throw Error("no control point " + std::to_string(i) + " to fix");
    fixed_[i] = true;
    v_.row(i).setZero();
  }
  factor();
}

void SolidModel::unfix(const std::vector<int>& points) {
  for (int i : points) {
    if (i < 0 || i >= control_.pointCount()) throw Error("no control point " + std::to_string(i) + " to unfix");
    fixed_[i] = false;
  }
  factor();
}

std::vector<int> SolidModel::fixedPoints() const {
  std::vector<int> points;
  for (int i = 0; i < control_.pointCount(); ++i)
    if (fixed_[i]) points.push_back(i);
  return points;
}

void SolidModel::factor() {
  auto solver = std::make_unique<Solver>();
  solver->freeIndex.assign(control_.pointCount(), -1);
  int free = 0;
  for (int i = 0; i < control_.pointCount(); ++i)
    if (!fixed_[i]) solver->freeIndex[i] = free++;
  std::vector<Eigen::Triplet<double>> triplets;
  for (int r = 0; r < refined_.A.outerSize(); ++r)
    for (SparseMatrix::InnerIterator it(refined_.A, r); it; ++it)
      if (solver->freeIndex[it.col()] >= 0) triplets.emplace_back(r, solver->freeIndex[it.col()], it.value());
  solver->A1.resize(refined_.A.rows(), free);
  solver->A1.setFromTriplets(triplets.begin(), triplets.end());
  if (free > 0) {
    const Eigen::SparseMatrix<double> mass = material_.mass * Eigen::SparseMatrix<double>(solver->A1.transpose() * solver->A1);
    solver->ldlt.compute(mass);
    if (solver->ldlt.info() != Eigen::Success) throw Error("the solid's mass matrix A1^T M A1 could not be factored");
  }
  solver_ = std::move(solver);
}

void SolidModel::rope(int dataPoint, const Vector3& target, double stiffness) {
  if (dataPoint < 0 || dataPoint >= refined_.lattice.pointCount()) throw Error("no mass point " + std::to_string(dataPoint));
  if (!(std::isfinite(stiffness) && stiffness > 0) || !target.allFinite())
    throw Error("the rope needs a finite target and a stiffness > 0");
  ropePoint_ = dataPoint;
  ropeTarget_ = target;
  ropeStiffness_ = stiffness;
}

void SolidModel::releaseRope() { ropePoint_ = -1; }

int SolidModel::nearestDataPoint(const Vector3& point) const {
  const MatrixX3 d = dataPoints();
  Eigen::Index best = 0;
  (d.rowwise() - point.transpose()).rowwise().squaredNorm().minCoeff(&best);
  return static_cast<int>(best);
}

void SolidModel::resetRestLengths() {
  const MatrixX3 d = dataPoints();
  springs_->normalRest.clear();
  for (const auto& [a, b] : springs_->normal) springs_->normalRest.push_back((d.row(a) - d.row(b)).norm());
  springs_->virtualRest.clear();
  for (const auto& [m, a, b] : springs_->virtuals)
    springs_->virtualRest.push_back((0.5 * (d.row(a) + d.row(b)) - d.row(m)).norm());
}

MatrixX3 SolidModel::springForces(const MatrixX3& d, double* energy) const {
  MatrixX3 f = MatrixX3::Zero(d.rows(), 3);
  double stored = 0;
  for (std::size_t s = 0; s < springs_->normal.size(); ++s) {
    const auto [a, b] = springs_->normal[s];
    const Eigen::RowVector3d delta = d.row(b) - d.row(a);
    const double length = delta.norm(), stretch = length - springs_->normalRest[s];
    stored += 0.5 * material_.springStiffness * stretch * stretch;
    if (length <= 0) continue;
    const Eigen::RowVector3d pull = material_.springStiffness * stretch / length * delta;
    f.row(a) += pull;
    f.row(b) -= pull;
  }
  for (std::size_t s = 0; s < springs_->virtuals.size(); ++s) {
    const auto [m, a, b] = springs_->virtuals[s];
    const Eigen::RowVector3d delta = 0.5 * (d.row(a) + d.row(b)) - d.row(m);
    const double length = delta.norm(), stretch = length - springs_->virtualRest[s];
    stored += 0.5 * material_.virtualStiffness * stretch * stretch;
    if (length <= 0) continue;
    const Eigen::RowVector3d pull = material_.virtualStiffness * stretch / length * delta;
    f.row(m) += pull;
    f.row(a) -= 0.5 * pull;  // the massless virtual point passes its reaction on
    f.row(b) -= 0.5 * pull;
  }
  if (energy) *energy = stored;
  return f;
}

void SolidModel::step(double dt, SolidScheme scheme) {
  if (!(std::isfinite(dt) && dt > 0)) throw Error("the time step must be finite and > 0");
  const Solver& s = *solver_;
  if (s.A1.cols() == 0) return;  // everything fixed
  const MatrixX3 d = dataPoints();
  MatrixX3 f = springForces(d) - material_.damping * (refined_.A * v_);
  if (ropePoint_ >= 0) f.row(ropePoint_) += ropeStiffness_ * (ropeTarget_.transpose() - d.row(ropePoint_));
  const MatrixX3 acceleration = s.ldlt.solve(MatrixX3(s.A1.transpose() * f));
  MatrixX3 p = p_, v = v_;
  for (int i = 0; i < control_.pointCount(); ++i) {
    const int r = s.freeIndex[i];
    if (r < 0) continue;
    if (scheme == SolidScheme::PaperExplicit) {
      p.row(i) += dt * v.row(i);
      v.row(i) += dt * acceleration.row(r);
    } else {
      v.row(i) += dt * acceleration.row(r);
      p.row(i) += dt * v.row(i);
    }
  }
  // A step that overshoots grows the points geometrically; they pass any
  // coordinate a model may have well before they turn non-finite.
  if (!p.allFinite() || !v.allFinite() || p.cwiseAbs().maxCoeff() > kLargestCoordinate)
    throw Error("the solid's simulation diverged: the time step " + std::to_string(dt) +
                " s is too large for its stiffness and damping");
  p_ = std::move(p);
  v_ = std::move(v);
}

double SolidModel::kineticEnergy() const {
  return 0.5 * material_.mass * (refined_.A * v_).squaredNorm();
}

double SolidModel::springEnergy() const {
  double energy = 0;
  springForces(dataPoints(), &energy);
  return energy;
}

}  // namespace dynsub
