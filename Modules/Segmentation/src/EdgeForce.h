#pragma once
// The image force of eq. 28 as the dynamics take it: k grad(P) / |grad(P)|
// (N/mm^2 of surface), sampled from an EdgeField at the surface's points.
#include "dynsub/EdgePotential.h"
#include "dynsub/Forces.h"

namespace dynsub {

class EdgeForce final : public ForceField {
 public:
  // `field` is not owned and must outlive this; `strength` is k.
  EdgeForce(const EdgeField& field, double strength) : field_(field), strength_(strength) {}
  MatrixX3 forcesAt(const MatrixX3& points) const override { return strength_ * field_.sample(points); }
  // The field's directions can reverse between neighbouring voxels (EdgeField::slopeBound).
  double slopeBound() const override { return strength_ * field_.slopeBound(); }

 private:
  const EdgeField& field_;
  double strength_;
};

}  // namespace dynsub
