// The static scheme's Newton matrix (StaticSolver.h).
#include <gtest/gtest.h>

#include <random>

#include <unsupported/Eigen/KroneckerProduct>

#include "dynsub/ForceModel.h"
#include "dynsub/LimitSurface.h"
#include "dynsub/StandardMeshes.h"
#include "dynsub/StaticSolver.h"

namespace dynsub {
namespace {

// The 3N x 3N Newton matrix against its definition, built densely:
// K (x) I_3 + sum_q (J_q^T J_q) (x) B_q, unknown 3 v + a. 400 points: from
// 256 on, the points' sums are shared between threads (on a machine with more
// than one core), which must give the definition, and the same bits from one
// build to the next. (That a serial build gives those bits too follows from
// each element's sums being made by one thread; this test cannot choose the
// thread count.)
TEST(TangentStiffness, MatchesItsDenseDefinition) {
  const ControlMesh mesh = makeCube98();
  const LimitSurface surface(mesh);
  const PhysicalMatrices m = assemblePhysicalMatrices(surface, Material{});
  TangentStiffness h(surface), again(surface);
  h.reset(m.stiffness);
  again.reset(SymmetricMatrix(2.0 * m.stiffness));
  again.resetToLast();
  again.reset(m.stiffness);
  const int n = surface.controlVertexCount();
  Eigen::MatrixXd expected = Eigen::kroneckerProduct(Eigen::MatrixXd(m.stiffness), Eigen::Matrix3d::Identity());
  std::mt19937_64 random(3);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (int i = 0; i < 400; ++i) {
    const ElementPoint q{static_cast<int>(unit(random) * surface.elementCount()) % surface.elementCount(), unit(random),
                         unit(random)};
    Eigen::Matrix3d b = Eigen::Matrix3d::Random();
    b = (b * b.transpose()).eval();
    h.addPoint(q, b);
    again.addPoint(q, b);
    const Eigen::VectorXd j = Eigen::RowVectorXd(surface.limitOperator({q}).row(0)).transpose();
    expected += Eigen::kroneckerProduct(Eigen::MatrixXd(j * j.transpose()), b);
  }
  const SparseMatrix scalar = springStiffness(surface, {Spring{ElementPoint{5, 0.3, 0.6}, Vector3::Zero(), 2.0}});
  h.addScalar(scalar);
  again.addScalar(scalar);
  expected += Eigen::kroneckerProduct(Eigen::MatrixXd(scalar), Eigen::Matrix3d::Identity());
  const Eigen::MatrixXd actual(h.matrix());
  ASSERT_EQ(actual.rows(), 3 * n);
  // The lower triangle alone is stored.
  expected = Eigen::MatrixXd(expected.triangularView<Eigen::Lower>());
  // Sums of the same products in another order: rounding of ~1e-15 of the entries.
  EXPECT_LT((actual - expected).cwiseAbs().maxCoeff(), 1e-12 * expected.cwiseAbs().maxCoeff());
  EXPECT_EQ(Eigen::MatrixXd(again.matrix()), actual);

  // A new step from K alone (the Newton steps of a level): the points are gone.
  h.resetToLast();
  const Eigen::MatrixXd k = Eigen::kroneckerProduct(Eigen::MatrixXd(m.stiffness), Eigen::Matrix3d::Identity());
  EXPECT_EQ(Eigen::MatrixXd(h.matrix()), Eigen::MatrixXd(k.triangularView<Eigen::Lower>()));
}

}  // namespace
}  // namespace dynsub
