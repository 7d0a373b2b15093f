#pragma once
// A bright ball (radius 12 mm, intensity 100 on 0) in an image whose axes are
// rotated and tilted, with anisotropic voxels: where things must line up.
#include <cmath>
#include <vector>

#include <Eigen/Geometry>

#include "dynsub/Landmarks.h"
#include "dynsub/Volume.h"

namespace dynsub {

struct BallPhantom {
  Volume image;
  Vector3 centre{4.0, -7.0, 11.0};
  double radius = 12.0;
};

inline BallPhantom makeBallPhantom() {
  BallPhantom p;
  ImageGeometry& g = p.image.geometry;
  g.size = {48, 56, 30};
  g.spacing = Vector3(0.9, 0.8, 1.5);
  g.direction = (Eigen::AngleAxisd(0.35, Vector3::UnitZ()) * Eigen::AngleAxisd(0.17, Vector3::UnitX()))
                    .toRotationMatrix() *
                Vector3(-1, -1, 1).asDiagonal();
  g.origin = Vector3::Zero();
  // Centre the grid on the ball.
  const Vector3 middle(0.5 * (g.size[0] - 1), 0.5 * (g.size[1] - 1), 0.5 * (g.size[2] - 1));
  g.origin = p.centre - g.toPhysical(middle);
  p.image.voxels.resize(g.voxelCount());
  for (int k = 0; k < g.size[2]; ++k)
    for (int j = 0; j < g.size[1]; ++j)
      for (int i = 0; i < g.size[0]; ++i)
        p.image.voxels[g.offset(i, j, k)] = (g.toPhysical(Vector3(i, j, k)) - p.centre).norm() <= p.radius ? 100 : 0;
  return p;
}

// n points spread evenly over the ball's surface (a Fibonacci sphere).
inline std::vector<Landmark> ballLandmarks(const BallPhantom& p, int n) {
  std::vector<Landmark> marks;
  const double golden = M_PI * (3.0 - std::sqrt(5.0));
  for (int i = 0; i < n; ++i) {
    const double z = 1.0 - 2.0 * (i + 0.5) / n, r = std::sqrt(1.0 - z * z);
    const Vector3 direction(r * std::cos(golden * i), r * std::sin(golden * i), z);
    marks.push_back({"B-" + std::to_string(i + 1), p.centre + p.radius * direction});
  }
  return marks;
}

}  // namespace dynsub
