// Properties of the assembled mass, damping and stiffness matrices with exact
// answers: partition of unity (mass sums to mu x area), constants in the null
// space of K, symmetry and definiteness, exactness of the quadrature, agreement
// with an independent composite quadrature of the limit operators, and
// invariance of the energy under global refinement.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>

#include "TestMeshes.h"
#include "dynsub/CatmullClark.h"
#include "dynsub/Error.h"
#include "dynsub/GaussLegendre.h"
#include "dynsub/LimitSurface.h"
#include "dynsub/PhysicalMatrices.h"
#include "dynsub/StandardMeshes.h"
#include "dynsub/Topology.h"

namespace dynsub {
namespace {

using testing::NamedMesh;

class PhysicalMatricesTest : public ::testing::TestWithParam<NamedMesh> {};

Eigen::MatrixXd dense(const SymmetricMatrix& m) { return Eigen::MatrixXd(m); }

TEST_P(PhysicalMatricesTest, MassSumsToDensityTimesParametricArea) {
  const LimitSurface surface(GetParam().mesh);
  Material material;
  material.mass = 2.5;
  const PhysicalMatrices m = assemblePhysicalMatrices(surface, material);
  // Rows of J sum to 1, so 1^T M 1 = mu x area; the special elements omit a
  // corner square of area 4^-24 each, far below the 1e-12 tolerance.
  EXPECT_NEAR(m.mass.sum(), 2.5 * surface.elementCount(), 1e-12 * surface.elementCount());
  EXPECT_NEAR(m.damping.sum(), material.damping * surface.elementCount(), 1e-11 * surface.elementCount());
}

// The assembly sums each element's integrals in place on the shared pattern;
// setFromTriplets over the same integrals, in the same element order, must
// give the same matrices to the bit.
TEST_P(PhysicalMatricesTest, AssemblyIsTheSumOfTheElementIntegrals) {
  const LimitSurface surface(GetParam().mesh);
  const Material material;
  const PhysicalMatrices m = assemblePhysicalMatrices(surface, material);
  std::vector<Eigen::Triplet<double>> mass, stiffness;
  for (int e = 0; e < surface.elementCount(); ++e) {
    const ElementIntegrals in = integrateElement(surface, e);
    const Eigen::MatrixXd k = material.tensionU * in.tensionU + material.tensionV * in.tensionV +
                              material.rigidityUU * in.plateUU + material.rigidityUV * in.plateUV +
                              material.rigidityVV * in.plateVV;
    for (size_t j = 0; j < in.columns.size(); ++j) {
      for (size_t i = 0; i < in.columns.size(); ++i) {
        mass.emplace_back(in.columns[i], in.columns[j], material.mass * in.mass(i, j));
        stiffness.emplace_back(in.columns[i], in.columns[j], k(i, j));
      }
    }
  }
  const int n = surface.controlVertexCount();
  SymmetricMatrix expectedMass(n, n), expectedStiffness(n, n);
  expectedMass.setFromTriplets(mass.begin(), mass.end());
  expectedStiffness.setFromTriplets(stiffness.begin(), stiffness.end());
  EXPECT_EQ(dense(m.mass), dense(expectedMass));
  EXPECT_EQ(dense(m.stiffness), dense(expectedStiffness));
  EXPECT_EQ(m.stiffness.nonZeros(), expectedStiffness.nonZeros());
}

TEST_P(PhysicalMatricesTest, ConstantsAreInTheNullSpaceOfK) {
  const LimitSurface surface(GetParam().mesh);
  const PhysicalMatrices m = assemblePhysicalMatrices(surface, Material{});
  const Eigen::VectorXd ones = Eigen::VectorXd::Ones(m.stiffness.rows());
  const double scale = dense(m.stiffness).cwiseAbs().maxCoeff();
  // Derivative rows of J sum to 0 exactly up to rounding (~1e-13 relative).
  EXPECT_LT((m.stiffness * ones).cwiseAbs().maxCoeff(), 1e-10 * scale);
}

TEST_P(PhysicalMatricesTest, MatricesAreSymmetricAndDefinite) {
  const LimitSurface surface(GetParam().mesh);
  const PhysicalMatrices m = assemblePhysicalMatrices(surface, Material{});
  for (const SymmetricMatrix* a : {&m.mass, &m.stiffness}) {
    const Eigen::MatrixXd d = dense(*a);
    const double scale = d.cwiseAbs().maxCoeff();
    EXPECT_LT((d - d.transpose()).cwiseAbs().maxCoeff(), 1e-13 * scale);
    const Eigen::VectorXd eigenvalues = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(d).eigenvalues();
    if (a == &m.mass) {
      // The limit functions of distinct control vertices are linearly independent.
      EXPECT_GT(eigenvalues.minCoeff(), 0.0);
    } else {
      EXPECT_GT(eigenvalues.minCoeff(), -1e-10 * scale);  // semi-definite: constants have energy 0
    }
  }
}

INSTANTIATE_TEST_SUITE_P(AllMeshes, PhysicalMatricesTest, ::testing::ValuesIn(testing::allTestMeshes()),
                         [](const auto& info) { return info.param.name; });

TEST(GaussLegendre, IntegratesPolynomialsOfDegree2nMinus1Exactly) {
  for (int n = 1; n <= 12; ++n) {
    const QuadratureRule rule = gaussLegendre(n);
    for (int degree = 0; degree <= 2 * n - 1; ++degree) {
      double sum = 0.0;
      for (int i = 0; i < n; ++i) sum += rule.weights[i] * std::pow(rule.nodes[i], degree);
      EXPECT_NEAR(sum, 1.0 / (degree + 1), 1e-14) << "n = " << n << ", degree " << degree;
    }
  }
}

// Tolerances below are relative to the largest entry of any of the element's matrices.
double largestEntry(const ElementIntegrals& e) {
  double m = 0.0;
  for (const Eigen::MatrixXd* a : {&e.mass, &e.tensionU, &e.tensionV, &e.plateUU, &e.plateUV, &e.plateVV}) {
    m = std::max(m, a->cwiseAbs().maxCoeff());
  }
  return m;
}

TEST(ElementIntegrals, FourPointQuadratureIsExact) {
  // The integrands are polynomials of degree <= 6 per variable: 4 points are
  // exact, so 8 points must agree to rounding.
  for (const NamedMesh& named : testing::allTestMeshes()) {
    const LimitSurface surface(named.mesh);
    AssemblyOptions four, eight;
    eight.quadraturePoints = 8;
    for (int e = 0; e < surface.elementCount(); e += 7) {
      const ElementIntegrals a = integrateElement(surface, e, four), b = integrateElement(surface, e, eight);
      const double scale = largestEntry(a);
      EXPECT_LT((a.mass - b.mass).cwiseAbs().maxCoeff(), 1e-14 * scale) << named.name << " element " << e;
      EXPECT_LT((a.tensionU - b.tensionU).cwiseAbs().maxCoeff(), 1e-13 * scale) << named.name;
      // Plate pieces at level 8 carry a factor 4^8: rounding grows to ~1e-11.
      EXPECT_LT((a.plateUU - b.plateUU).cwiseAbs().maxCoeff(), 1e-10 * scale) << named.name;
      EXPECT_LT((a.plateUV - b.plateUV).cwiseAbs().maxCoeff(), 1e-10 * scale) << named.name;
    }
  }
}

// An independent check of the piecewise assembly, including the quarter turns
// of special-element pieces: a composite 4 x 4 Gauss rule on a 32 x 32 grid of
// cells, with the limit operators of LimitSurface at every node. The grid
// lines are the piece boundaries of levels <= 5, so cut off at 5 levels (and
// without the extraordinary corner cell) both are exact and must agree.
TEST(ElementIntegrals, AgreeWithCompositeQuadratureOfTheLimitOperators) {
  for (const NamedMesh& named : testing::allTestMeshes()) {
    const LimitSurface surface(named.mesh);
    AssemblyOptions options;
    options.levels = 5;
    options.plateLevels = 5;
    const QuadratureRule rule = gaussLegendre(4);
    constexpr int cells = 32;
    for (int e = 0; e < surface.elementCount(); e += 9) {
      const ElementIntegrals exact = integrateElement(surface, e, options);
      int corner = -1;
      const Polygon& face = surface.baseTopology().face(e);
      for (int k = 0; k < 4; ++k) {
        if (!surface.baseTopology().isRegularVertex(face[k])) corner = k;
      }
      const int skipI = corner == 1 || corner == 2 ? cells - 1 : 0;
      const int skipJ = corner == 2 || corner == 3 ? cells - 1 : 0;
      std::vector<ElementPoint> points;
      std::vector<double> weights;
      for (int cj = 0; cj < cells; ++cj) {
        for (int ci = 0; ci < cells; ++ci) {
          if (corner >= 0 && ci == skipI && cj == skipJ) continue;
          for (int j = 0; j < 4; ++j) {
            for (int i = 0; i < 4; ++i) {
              points.push_back(ElementPoint{e, (ci + rule.nodes[i]) / cells, (cj + rule.nodes[j]) / cells});
              weights.push_back(rule.weights[i] * rule.weights[j] / (cells * cells));
            }
          }
        }
      }
      const LimitOperators ops = surface.operators(points);
      const Eigen::Map<const Eigen::VectorXd> w(weights.data(), static_cast<Eigen::Index>(weights.size()));
      auto integral = [&](const SparseMatrix& J) {
        const Eigen::MatrixXd full = Eigen::MatrixXd(J.transpose() * w.asDiagonal() * J);
        return Eigen::MatrixXd(full(exact.columns, exact.columns));
      };
      const double scale = largestEntry(exact);
      EXPECT_LT((integral(ops.J) - exact.mass).cwiseAbs().maxCoeff(), 1e-12 * scale) << named.name << " " << e;
      EXPECT_LT((integral(ops.Ju) - exact.tensionU).cwiseAbs().maxCoeff(), 1e-11 * scale) << named.name << " " << e;
      EXPECT_LT((integral(ops.Jv) - exact.tensionV).cwiseAbs().maxCoeff(), 1e-11 * scale) << named.name << " " << e;
      EXPECT_LT((integral(ops.Juu) - exact.plateUU).cwiseAbs().maxCoeff(), 1e-10 * scale) << named.name << " " << e;
      EXPECT_LT((integral(ops.Juv) - exact.plateUV).cwiseAbs().maxCoeff(), 1e-10 * scale) << named.name << " " << e;
      EXPECT_LT((integral(ops.Jvv) - exact.plateVV).cwiseAbs().maxCoeff(), 1e-10 * scale) << named.name << " " << e;
    }
  }
}

// A refined control mesh has the same limit surface (q = A p), and elements of
// half the side: its energy of the same surface must be the same,
// A^T M_1 A = M_0. The rigidity cut-off sits at the same place in space when
// level 1 keeps one level less of it.
TEST(PhysicalMatrices, EnergyIsUnchangedByGlobalRefinement) {
  for (const char* name : {"cube", "torus"}) {
    const ControlMesh mesh = makeStandardMesh(name);
    const SubdividedMesh refined = subdivide(mesh);
    AssemblyOptions coarse, fine;
    coarse.plateLevels = 9;
    fine.plateLevels = 8;
    fine.levels = 23;  // the same corner square as 24 levels at level 0
    fine.elementSize = 0.5;
    const PhysicalMatrices m0 = assemblePhysicalMatrices(LimitSurface(mesh), Material{}, coarse);
    const PhysicalMatrices m1 = assemblePhysicalMatrices(LimitSurface(refined.mesh), Material{}, fine);
    const Eigen::MatrixXd A = Eigen::MatrixXd(refined.subdivisionMatrix);
    const Eigen::MatrixXd mass = A.transpose() * dense(m1.mass) * A;
    const Eigen::MatrixXd stiffness = A.transpose() * dense(m1.stiffness) * A;
    EXPECT_LT((mass - dense(m0.mass)).cwiseAbs().maxCoeff(), 1e-12 * dense(m0.mass).cwiseAbs().maxCoeff()) << name;
    EXPECT_LT((stiffness - dense(m0.stiffness)).cwiseAbs().maxCoeff(),
              1e-10 * dense(m0.stiffness).cwiseAbs().maxCoeff())
        << name;
  }
}

TEST(PhysicalMatrices, RejectsBadParameters) {
  const LimitSurface surface(makeCube98());
  Material negative;
  negative.tensionU = -1.0;
  EXPECT_THROW(assemblePhysicalMatrices(surface, negative), Error);
  Material nan;
  nan.mass = std::nan("");
  EXPECT_THROW(assemblePhysicalMatrices(surface, nan), Error);
  AssemblyOptions options;
  options.plateLevels = 30;
  EXPECT_THROW(assemblePhysicalMatrices(surface, Material{}, options), Error);
  EXPECT_THROW(assemblePhysicalMatrices(surface, std::vector<Material>(3)), Error);
}

}  // namespace
}  // namespace dynsub
