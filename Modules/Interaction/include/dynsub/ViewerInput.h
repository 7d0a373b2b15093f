#pragma once
// What the viewer (Viewer.h) is opened with, in the project's own types.
#include <string>
#include <vector>

#include "dynsub/Landmarks.h"
#include "dynsub/Segmentation.h"

namespace dynsub {

struct ViewerInput {
  Volume image;
  std::vector<Landmark> landmarks;
  std::string landmarksPath = "landmarks.mrk.json";  // where s saves and l loads
  std::string surfacePath;  // optional: a surface file (SurfacePolyData.h) shown until a fit starts
  SegmentOptions segment;
  double initialFraction = 0.5;  // the start inside the landmarks' PCA ellipsoid (initialFromLandmarks)
  double pullStiffness = 20.0;  // N/mm, the 3D view's pulling spring
};

}  // namespace dynsub
