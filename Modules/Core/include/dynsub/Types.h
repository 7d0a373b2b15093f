#pragma once
// Eigen aliases shared by all modules. Points are rows of an N x 3 matrix in mm.
#include <Eigen/Core>
#include <Eigen/Geometry>  // cross products
#include <Eigen/SparseCore>

namespace dynsub {

using Vector3 = Eigen::Vector3d;
using Matrix3 = Eigen::Matrix3d;
using MatrixX3 = Eigen::Matrix<double, Eigen::Dynamic, 3>;  // N x 3, one point per row
// Sparse linear operators over control vertices: rows are outputs, columns inputs.
using SparseMatrix = Eigen::SparseMatrix<double, Eigen::RowMajor>;
using Triplet = Eigen::Triplet<double>;

}  // namespace dynsub
