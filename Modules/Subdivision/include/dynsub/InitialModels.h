#pragma once
// The papers' initial models, placed in space: the 98-vertex cube (TVCG
// Fig. 3) as an ellipsoid or a sphere, and the 32-vertex torus, sized by
// their limit surfaces. Fitting and segmentation both start from these.
#include <string>

#include "dynsub/ControlMesh.h"
#include "dynsub/Coordinates.h"
#include "dynsub/Types.h"

namespace dynsub {

// The smallest extent (mm) of a point cloud checkPointCloud accepts: a
// nanometre-scale scan.
constexpr double kSmallestSpan = 1e-6;

// Checks a point cloud read from `source`: at least 4 points, finite
// coordinates within kLargestCoordinate of the origin, a span of at least
// kSmallestSpan unless they all coincide, not all coincident, not all on a
// plane or a line. Throws dynsub::Error naming the source.
void checkPointCloud(const MatrixX3& points, const std::string& source);

// The dimensions finite points span, by checkPointCloud's test: 0 when they
// all coincide, 1 on a line, 2 on a plane, 3 when they enclose a volume.
int spannedDimensions(const MatrixX3& points);

// The 98-vertex cube whose limit surface spans `semiAxes` (mm) along the
// columns of `axes` (orthonormal, right-handed) around `centre`: its
// control points scaled so that the limit surface's largest coordinate along
// each axis is that semi-axis.
ControlMesh cubeInEllipsoid(const Vector3& centre, const Matrix3& axes, const Vector3& semiAxes);

enum class InitialShape { Sphere, Torus };

// The papers' initial model placed inside the data's PCA ellipsoid. Sphere:
// the cube in `fraction` (by default half) of the ellipsoid's semi-axes
// (sqrt(3 lambda_i): exact for points spread over an ellipsoid's surface).
// Torus: the 32-vertex torus around the axis of least variance, with the
// data's mean ring radius and half its mean tube radius.
ControlMesh initialModel(const MatrixX3& points, InitialShape shape, double fraction = 0.5);

// The cube as a sphere of `radius` mm around `centre`: scaled equally along
// every axis so that its limit surface's mean distance from the centre (on
// a 4 x 4 tessellation) is `radius`; its corners reach a little further than
// its axes.
// Throws dynsub::Error for a radius that is not > 0 or a centre that is not
// finite.
ControlMesh initialSphere(const Vector3& centre, double radius);

}  // namespace dynsub
