#pragma once
// One segmentation from its inputs to its report: the initial model, the
// evolution with its convergence record, and the numbers and warnings of
// report.json. Shared by `dynsub segment` and the 3D Slicer module
// DynSubSegment, so that both run and report the same thing.
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "dynsub/ConvergenceHistory.h"
#include "dynsub/Landmarks.h"
#include "dynsub/Metrics.h"
#include "dynsub/Report.h"
#include "dynsub/SeedGrowth.h"
#include "dynsub/Segmentation.h"

namespace dynsub::app {

// Where the evolution starts.
struct InitialModel {
  enum class Kind {
    FromLandmarks,  // the 98-vertex cube inside the landmarks' PCA ellipsoid
    Sphere,         // `center`, `radius`
    Seed,           // one click inside the structure at `center` (SeedGrowth.h)
    Mesh,           // a closed control mesh read from `meshPath`
  };
  Kind kind = Kind::FromLandmarks;
  Vector3 center = Vector3::Zero();  // LPS mm
  double radius = 0;
  std::string meshPath;
  std::string text;  // as the user gave it, for report.json
};

// "auto", "sphere:x,y,z,r", "seed:x,y,z" or a mesh path; `option` names the
// flag in errors. Throws dynsub::Error on malformed or non-finite numbers.
InitialModel parseInitialModel(const std::string& value, const std::string& option);

struct SegmentInputs {
  std::string image;                // the file, for the report
  std::string landmarkSource;       // the file or flag the landmarks came from, for messages
  std::vector<Landmark> landmarks;  // may be empty with a seed, sphere or mesh start
  InitialModel init;
  SegmentOptions segment;
  SeedOptions seed;
  std::string potential = "edges";  // its name, for the report
  // Optional: the structure in an expert's labelmap on the image's grid,
  // asked for once the segmentation is done (so that it can be read
  // meanwhile); it may throw, as reading it would.
  std::function<const Mask&()> reference;
  std::string referencePath;
  std::vector<int> referenceLabels;
};

struct SegmentRun {
  SegmentResult result;
  Mask labelmap;                     // result.surface on the image's grid (Labelmap.h)
  std::unique_ptr<SeedRegion> seed;  // for a seed start
  std::vector<Landmark> springs;     // what the springs pulled to
  OverlapMetrics metrics;            // against the reference, when given
  ConvergenceHistory history;
  std::vector<std::string> warnings;  // the seed's and the segmentation's
  double seconds = 0;
  Report report;
};

// Runs the segmentation; `progress` (may be empty) sees every step. Throws
// dynsub::Error naming the landmark source when the landmarks cannot be used.
SegmentRun runSegmentation(const Volume& image, SegmentInputs inputs, const ProgressCallback& progress);

// How far the structure's tissue was followed past the outermost clicked
// slices where a spring or the pressure then acted (SliceEnds.h), e.g. "10.0
// mm before the first, 4.5 mm after the last (no end seen)"; empty when
// nothing acted past either. A user whose clicks reach the structure's ends
// needs this to know to turn it off.
std::string carriedPastSlices(const SegmentResult& result);

}  // namespace dynsub::app
