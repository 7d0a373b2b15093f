#pragma once
// The mass, damping and stiffness matrices of a dynamic Catmull-Clark surface
// (TVCG 1998 eqs 18-20 and §3.1; ICCV 1998 eqs 14-16):
//   M = ∫∫ mu J^T J,  D = ∫∫ gamma J^T J,
//   K = ∫∫ alpha11 J_u^T J_u + alpha22 J_v^T J_v
//          + beta11 J_uu^T J_uu + beta12 J_uv^T J_uv + beta22 J_vv^T J_vv,
// each #control vertices by #control vertices, applied to x, y and z alike.
//
// Parameter domain. Integrals run over the elements' parameters with every
// element of the *initial* model a unit square; after g global refinements an
// element is a square of side `elementSize` = 2^-g. So the energy of a given
// limit surface does not depend on how often its control mesh was refined
// (A^T M_g A = M_0 exactly; the same for K up to the plate truncation below).
//
// Elements. A normal element is one bicubic B-spline patch; a special element
// the pieces of local subdivision around its extraordinary vertex (TVCG eq.
// 26): each piece contributes Omega^T M_p Omega with Omega its 16 control
// points over the element's control vertices and M_p the unit-square B-spline
// integral scaled by its side L: L^2 for mass and damping, 1 for the tension
// (first-derivative) terms, L^-2 for the plate (second-derivative) terms. The
// unit-square integrals are polynomials of degree <= 6 per variable, computed
// exactly by 4-point Gauss-Legendre quadrature.
//
// Truncation. Mass, damping and tension sum levels 1..24: the omitted corner
// square has area 4^-24 ≈ 3.6e-15 of the element. The plate terms diverge at
// an extraordinary vertex of valence >= 5 (per-level energy grows like
// (2 lambda)^(2 level), lambda > 1/2 the subdominant eigenvalue), so following
// TVCG §2.5 ("zero rigidity at extraordinary points") and §3.1.2 (patches
// below the display resolution are ignored) the rigidity is zero inside the
// corner square of side 2^-plateLevels (default 2^-8: 0.04 mm on a 10 mm
// element, far below any image resolution). See Documentation/Dynamics.md for
// its measured effect on the energy.
//
// Units: positions in mm, parameters dimensionless. mu in kg and gamma in
// kg/s per unit parametric area; alpha and beta in N/mm per unit parametric
// area, so p^T K p / 2 is in N mm (mJ).
#include <vector>

#include "dynsub/Types.h"

namespace dynsub {

class LimitSurface;

struct Material {
  double mass = 1.0;        // mu
  double damping = 10.0;    // gamma
  // Defaults are weak against the data (ShapeRecovery.h: 100 N/mm per unit
  // area): at 1.0 the tension and plate terms bias a fitted torus by ~2 % of
  // its size, at 0.1 by < 0.6 % (Documentation/Dynamics.md).
  double tensionU = 0.1;    // alpha11
  double tensionV = 0.1;    // alpha22
  double rigidityUU = 0.1;  // beta11
  double rigidityUV = 0.2;  // beta12 (2 beta11 makes the plate energy rotation-invariant)
  double rigidityVV = 0.1;  // beta22

  // This material with its tension and rigidity times `factor`.
  Material withElasticity(double factor) const {
    Material m = *this;
    for (double* k : {&m.tensionU, &m.tensionV, &m.rigidityUU, &m.rigidityUV, &m.rigidityVV}) *k *= factor;
    return m;
  }
};

struct AssemblyOptions {
  double elementSize = 1.0;  // side of every element in parametric units (2^-refinements)
  int levels = 24;           // local-subdivision levels of a special element (mass, damping, tension)
  int plateLevels = 8;       // levels that carry rigidity (<= levels)
  int quadraturePoints = 4;  // Gauss-Legendre nodes per direction on a piece (4 is exact)
};

// The unit-material integrals of one element over its columns (control vertices).
struct ElementIntegrals {
  std::vector<int> columns;
  Eigen::MatrixXd mass;                   // ∫∫ J^T J
  Eigen::MatrixXd tensionU, tensionV;     // ∫∫ J_u^T J_u, ∫∫ J_v^T J_v
  Eigen::MatrixXd plateUU, plateUV, plateVV;
};

ElementIntegrals integrateElement(const LimitSurface& surface, int element, const AssemblyOptions& options = {});

// Column-major for the sparse solvers; symmetric.
using SymmetricMatrix = Eigen::SparseMatrix<double, Eigen::ColMajor>;

struct PhysicalMatrices {
  SymmetricMatrix mass, damping, stiffness;
};

// The pattern of every matrix summed over elements (#control by #control,
// column-major, compressed, rows sorted, values 0): an entry for every pair
// of control vertices that share an element. Throws dynsub::Error if an
// element's columns are not sorted (the in-place sums walk them in order).
SymmetricMatrix elementPattern(const LimitSurface& surface);

// One material per element (surface.elementCount()), or one for all.
// Throws dynsub::Error for negative or non-finite parameters or bad options.
PhysicalMatrices assemblePhysicalMatrices(const LimitSurface& surface, const std::vector<Material>& materials,
                                          const AssemblyOptions& options = {});
PhysicalMatrices assemblePhysicalMatrices(const LimitSurface& surface, const Material& material,
                                          const AssemblyOptions& options = {});

void checkMaterial(const Material& material);

}  // namespace dynsub
