#include "dynsub/Sculpting.h"

#include <cmath>
#include <limits>

#include "dynsub/Error.h"

namespace dynsub {

namespace {

// Of the point sets `use` accepts, the one whose centroid is nearest `point`.
template <typename Use>
int nearestCentroid(const MatrixX3& points, const std::vector<std::vector<int>>& sets, const Vector3& point, Use use) {
  int best = -1;
  double nearest = std::numeric_limits<double>::infinity();
  for (int i = 0; i < static_cast<int>(sets.size()); ++i) {
    if (!use(i)) continue;
    const double d = (centroidOf(points, sets[i]) - point).squaredNorm();
    if (d < nearest) {
      nearest = d;
      best = i;
    }
  }
  return best;
}

}  // namespace

Sculpture::Sculpture(const Lattice& control, const SculptSettings& settings) : settings_(settings), rest_(control) {
  if (!(std::isfinite(settings.timeStep) && settings.timeStep > 0))
    throw Error("the sculpting time step must be finite and > 0");
  if (!(std::isfinite(settings.ropeStiffness) && settings.ropeStiffness > 0))
    throw Error("the rope's stiffness must be finite and > 0");
  model_ = std::make_unique<SolidModel>(control, settings.levels, settings.material);
}

Sculpture::~Sculpture() = default;

Lattice Sculpture::control() const {
  Lattice lattice = rest_;
  lattice.setPoints(model_->controlPoints());
  return lattice;
}

void Sculpture::rebuild(const Lattice& rest, const MatrixX3& current, const std::vector<int>& fixed) {
  auto model = std::make_unique<SolidModel>(rest, settings_.levels, settings_.material);
  model->setControlPoints(current);
  if (!fixed.empty()) model->fix(fixed);
  rest_ = rest;
  model_ = std::move(model);
}

void Sculpture::grab(const Vector3& near) {
  if (!near.allFinite()) throw Error("the rope needs a finite point to grab");
  const int point = model_->nearestDataPoint(near);
  model_->rope(point, model_->dataPoints().row(point).transpose(), settings_.ropeStiffness);
}

void Sculpture::pullTo(const Vector3& target) {
  if (!roped()) throw Error("there is no rope to pull: grab a point first");
  model_->rope(model_->ropePoint(), target, settings_.ropeStiffness);
}

void Sculpture::release() { model_->releaseRope(); }

int Sculpture::extrude(int face) {
  const Lattice current = control();
  // The same tool on both shapes gives the same numbering; old points keep
  // theirs, and the new cell's outer face is the first new face (Lattice.cpp).
  const Lattice grown = extrudeFace(current, face);
  const int outer = current.faceCount();
  rebuild(extrudeFace(rest_, face), grown.points(), model_->fixedPoints());
  return outer;
}

void Sculpture::deleteCell(int cell) {
  const Lattice current = control();
  std::vector<int> kept;
  const Lattice smaller = dynsub::deleteCell(current, cell, &kept);
  std::vector<int> fixed;
  for (int i : model_->fixedPoints())
    if (kept[i] >= 0) fixed.push_back(kept[i]);
  rebuild(dynsub::deleteCell(rest_, cell), smaller.points(), fixed);
}

void Sculpture::fix(const std::vector<int>& points) { model_->fix(points); }
void Sculpture::unfix(const std::vector<int>& points) { model_->unfix(points); }
void Sculpture::unfixAll() { model_->unfix(model_->fixedPoints()); }

void Sculpture::plasticity() {
  model_->resetRestLengths();
  rest_.setPoints(model_->controlPoints());
}

void Sculpture::setMaterial(const SolidMaterial& material) {
  model_->setMaterial(material);
  settings_.material = material;
}

void Sculpture::run(int count) {
  for (int i = 0; i < count; ++i) {
    model_->step(settings_.timeStep, settings_.scheme);
    ++steps_;
  }
}

int Sculpture::boundaryFaceNear(const Vector3& point) const {
  return nearestCentroid(model_->controlPoints(), rest_.faces(), point,
                         [&](int face) { return rest_.isBoundaryFace(face); });
}

int Sculpture::cellNear(const Vector3& point) const {
  return nearestCentroid(model_->controlPoints(), rest_.cellPoints(), point, [](int) { return true; });
}

}  // namespace dynsub
