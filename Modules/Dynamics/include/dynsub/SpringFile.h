#pragma once
// Spring files for modeling by forces (dynsub deform): one spring per line,
// "x y z" or "x y z stiffness" (mm, N/mm), separated by spaces and tabs, or
// by commas, or by semicolons (one kind per line); '#' starts a comment.
#include <string>

#include "dynsub/Types.h"

namespace dynsub {

// The stiffest spring: beside the surface's own stiffness (order 1-1000),
// one stiffer than this is past what double precision balances. Deforming
// the torus with one spring of 1e12 N/mm left a relative equilibrium
// residual of 4e-5; of 1e15, 0.86, reported as an equilibrium.
constexpr double kLargestSpringStiffness = 1e12;

struct SpringFile {
  MatrixX3 targets;           // one row per spring: the point in space it pulls towards
  Eigen::VectorXd stiffness;  // N/mm, > 0
};

// Springs without a stiffness of their own get `defaultStiffness`. Throws
// dynsub::Error naming the file and line for a missing file, a field that is
// not a number, a wrong number of fields, a value that is not finite, a
// target beyond kLargestCoordinate, a stiffness that is not positive or
// above kLargestSpringStiffness, or a file without springs.
SpringFile readSpringFile(const std::string& path, double defaultStiffness);

}  // namespace dynsub
