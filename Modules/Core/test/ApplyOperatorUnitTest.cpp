// applyOperator against Eigen's own sparse-times-dense product.
#include <random>

#include <gtest/gtest.h>

#include "dynsub/ApplyOperator.h"

namespace {

using dynsub::MatrixX3;
using dynsub::SparseMatrix;

SparseMatrix randomOperator(int rows, int cols, std::mt19937& random) {
  std::uniform_int_distribution<int> column(0, cols - 1);
  std::uniform_real_distribution<double> weight(-1.0, 1.0);
  std::vector<dynsub::Triplet> triplets;
  for (int r = 0; r < rows; ++r) {
    for (int k = 0; k < 1 + r % 17; ++k) triplets.emplace_back(r, column(random), weight(random));
  }
  SparseMatrix op(rows, cols);
  op.setFromTriplets(triplets.begin(), triplets.end());
  return op;
}

TEST(ApplyOperator, EqualsEigensProductToTheBit) {
  // The same sums in the same order: equal, not merely close.
  std::mt19937 random(5);
  const SparseMatrix op = randomOperator(500, 120, random);
  const MatrixX3 points = MatrixX3::Random(120, 3);
  const MatrixX3 expected = op * points;
  const MatrixX3 result = dynsub::applyOperator(op, points);
  ASSERT_EQ(result.rows(), 500);
  EXPECT_TRUE((result.array() == expected.array()).all());
  // Into a reused array of another size.
  MatrixX3 reused = MatrixX3::Constant(7, 3, 1.0);
  dynsub::applyOperator(op, points, reused);
  EXPECT_TRUE((reused.array() == expected.array()).all());
}

TEST(ApplyOperator, ReadsAnUncompressedOperator) {
  // After reserve() a matrix keeps room in each row: only its counted entries are read.
  std::mt19937 random(6);
  SparseMatrix op = randomOperator(50, 30, random);
  op.reserve(Eigen::VectorXi::Constant(50, 4));
  op.coeffRef(7, 29) = 2.5;  // found or inserted; the rows keep their spare room
  ASSERT_FALSE(op.isCompressed());
  const MatrixX3 points = MatrixX3::Random(30, 3);
  const MatrixX3 expected = op * points;
  EXPECT_TRUE((dynsub::applyOperator(op, points).array() == expected.array()).all());
}

TEST(ApplyOperators, EqualThreeApplicationsToTheBitAndRefuseOtherPatterns) {
  // Three operators on one pattern (the values differ, zeros included).
  std::mt19937 random(7);
  const SparseMatrix a = randomOperator(400, 90, random);
  SparseMatrix b = a, c = a;
  std::uniform_real_distribution<double> weight(-1.0, 1.0);
  for (Eigen::Index k = 0; k < a.nonZeros(); ++k) {
    b.valuePtr()[k] = k % 5 == 0 ? 0.0 : weight(random);
    c.valuePtr()[k] = weight(random);
  }
  const MatrixX3 points = MatrixX3::Random(90, 3);
  MatrixX3 ra, rb, rc;
  dynsub::applyOperators(a, b, c, points, ra, rb, rc);
  EXPECT_TRUE((ra.array() == dynsub::applyOperator(a, points).array()).all());
  EXPECT_TRUE((rb.array() == dynsub::applyOperator(b, points).array()).all());
  EXPECT_TRUE((rc.array() == dynsub::applyOperator(c, points).array()).all());
  // Another pattern (rows of other lengths) is refused, not misread.
  const SparseMatrix other = randomOperator(400, 90, random);
  EXPECT_THROW(dynsub::applyOperators(a, other, c, points, ra, rb, rc), std::invalid_argument);
}

TEST(ApplyOperator, EqualsEigensProductToTheBitForAColumnMajorOperator) {
  // The physical matrices' storage; many entries per result row, so another
  // order of summation would round otherwise. Also uncompressed (room kept
  // in each column after reserve()).
  std::mt19937 random(9);
  Eigen::SparseMatrix<double, Eigen::ColMajor> op = randomOperator(300, 300, random);
  const MatrixX3 points = MatrixX3::Random(300, 3);
  const MatrixX3 expected = op * points;
  EXPECT_TRUE((dynsub::applyOperator(op, points).array() == expected.array()).all());
  op.reserve(Eigen::VectorXi::Constant(300, 3));
  op.coeffRef(5, 299) += 0.75;
  ASSERT_FALSE(op.isCompressed());
  const MatrixX3 again = op * points;
  EXPECT_TRUE((dynsub::applyOperator(op, points).array() == again.array()).all());
}

TEST(ApplyTransposed, EqualsEigensTransposedProductToTheBitAndRefusesAMismatch) {
  // Many rows into few columns, so each result row sums many terms, where
  // another order of summation would round otherwise.
  std::mt19937 random(8);
  const SparseMatrix op = randomOperator(2000, 40, random);
  const MatrixX3 values = MatrixX3::Random(2000, 3);
  const MatrixX3 expected = op.transpose() * values;
  const MatrixX3 result = dynsub::applyTransposed(op, values);
  ASSERT_EQ(result.rows(), 40);
  EXPECT_TRUE((result.array() == expected.array()).all());
  EXPECT_THROW(dynsub::applyTransposed(op, MatrixX3::Random(1999, 3)), std::invalid_argument);
  // Uncompressed: only each row's counted entries are read.
  SparseMatrix roomy = op;
  roomy.reserve(Eigen::VectorXi::Constant(2000, 2));
  roomy.coeffRef(3, 39) += 0.5;
  ASSERT_FALSE(roomy.isCompressed());
  const MatrixX3 again = roomy.transpose() * values;
  EXPECT_TRUE((dynsub::applyTransposed(roomy, values).array() == again.array()).all());
}

TEST(ApplyOperator, AnEmptyOperatorGivesNoRows) {
  const SparseMatrix op(0, 4);
  EXPECT_EQ(dynsub::applyOperator(op, MatrixX3::Zero(4, 3)).rows(), 0);
}

}  // namespace
