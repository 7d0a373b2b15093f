#pragma once
// One segmentation from its inputs to its report: the start (from the
// landmarks, a click inside, a sphere, a control mesh or an atlas), the evolution
// (Segmentation.h) with its convergence record, the labelmap, the scores
// against a reference, and report.json. `dynsub segment`, the 3D Slicer module
// DynSubSegment and `dynsub evaluate` all run this, so all three segment and
// report alike; they only read their arguments and write what it returns.
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "dynsub/Atlas.h"
#include "dynsub/ConvergenceHistory.h"
#include "dynsub/LandmarkConvention.h"
#include "dynsub/Landmarks.h"
#include "dynsub/Metrics.h"
#include "dynsub/Report.h"
#include "dynsub/SegmentParameters.h"
#include "dynsub/Trust.h"

namespace dynsub {

// Where the evolution starts.
struct SegmentStart {
  enum class Kind {
    FromLandmarks,  // the papers' cube inside the landmarks' PCA ellipsoid
    Sphere,         // `center`, `radius`
    Seed,           // one click inside the structure at `center` (SeedGrowth.h)
    Mesh,           // a closed control mesh read from `meshPath`
    Atlas,          // the atlas's structure carried to the image (Atlas.h), with its prior
  };
  Kind kind = Kind::FromLandmarks;
  Vector3 center = Vector3::Zero();  // LPS mm
  double radius = 0;
  std::string meshPath;
  std::string text = "auto";  // as the user gave it, for report.json
};

// "auto", "sphere:x,y,z,r", "seed:x,y,z", "atlas" or a mesh path; `option` names the
// flag in errors. Throws dynsub::Error on malformed or non-finite numbers.
SegmentStart parseSegmentStart(const std::string& value, const std::string& option);
// "x,y,z": a point in LPS mm, as a click is given on a command line; throws
// dynsub::Error naming `option` on malformed or non-finite numbers.
Vector3 parsePoint(const std::string& text, const std::string& option);

struct SegmentInputs {
  std::string image;                // the file, for the report
  std::string landmarkSource;       // the file or flag the landmarks came from, for messages
  std::vector<Landmark> landmarks;  // may be empty with a seed, sphere or mesh start
  // The system the landmarks' source says they are in (readLandmarks);
  // points given as numbers are LPS. Named when they look misread.
  CoordinateSystem landmarkSystem = CoordinateSystem::LPS;
  SegmentStart start;
  // Optional: the structure in an expert's labelmap on the labelmap's grid,
  // asked for once the segmentation is done (so that it can be read
  // meanwhile); it may throw, as reading it would.
  std::function<const Mask&()> reference;
  std::string referencePath;
  std::vector<int> referenceLabels;
  // The labelmap's grid; the image's when not given (an evaluation scores
  // on its reference's own grid).
  std::optional<ImageGeometry> labelmapGrid;
  // An atlas start: the atlas, its structure's label values, and the image's
  // affine registration to it when one was made already (the structures of
  // one image share it; segmentImage makes it otherwise).
  std::shared_ptr<const Atlas> atlas;
  std::vector<int> atlasLabels;
  std::shared_ptr<const AtlasAffine> atlasAffine;
  // The structure's label carried to the image already, with the same
  // inputs (a structure segmented again keeps its first pass's); the
  // deformable registration is made otherwise.
  std::shared_ptr<const CarriedLabel> atlasCarried;
  // With an atlas start: a click inside the structure (LPS mm), which picks
  // the carried label's part and moves a misplaced one to it.
  std::optional<Vector3> inside;
  // An earlier segmentation of these inputs, whose surface and levels the
  // evolution resumes from (segment()'s `resume`): a structure segmented
  // again beside others (SegmentStructures.h).
  std::shared_ptr<const SegmentResult> resume;
};

struct SegmentOutcome {
  SegmentResult result;
  Mask labelmap;                     // result.surface voxelized (Labelmap.h)
  std::unique_ptr<SeedRegion> seed;  // for a seed start
  // For an atlas start: the registration (to reuse for the image's other
  // structures), the label carried to the image and the prior's points.
  std::shared_ptr<const AtlasAffine> atlasAffine;
  std::optional<CarriedLabel> carried;
  std::vector<Landmark> prior;
  // The atlas start's fit (SegmentImage.cpp, fitAtlasStart): the factor on
  // the fit's tension and rigidity of the start kept (the first whose
  // surface does not cross itself, else the one that crosses least; 1 when
  // the default's does not), and the pairs of its triangles that cross.
  double atlasStartElasticity = 1.0;
  int atlasStartCrossings = 0;
  std::vector<Landmark> springs;     // what the springs pulled to
  OverlapMetrics metrics;            // against the reference, when given
  ConvergenceHistory history;
  // The edges at the landmarks as read and misread (LandmarkConvention.h),
  // with 4 or more landmarks.
  std::optional<ConventionScores> convention;
  std::vector<std::string> warnings;  // the seed's and the segmentation's
  TrustMeasures trust;                // the result against what it rests on (Trust.h)
  std::vector<TrustFlag> trustFlags;  // why not to trust it; empty when nothing says so
  double seconds = 0;                 // the start, the evolution and the labelmap
  Report report;
};

// Whether the start can be built from what the inputs give (at least 4
// landmarks for a start from them) and the parameters are possible with
// them; throws dynsub::Error saying what would do. segmentImage() checks
// this first; a command checks it before it writes anything.
void checkSegmentInputs(const SegmentInputs& inputs, const SegmentParameters& parameters);

// Throws dynsub::Error naming the image when the click inside (--inside)
// lies outside it: checked before an atlas's registration, which takes seconds.
void requireInsideClickInImage(const Volume& image, const SegmentInputs& inputs);

// Throws dynsub::Error naming the landmark source when the landmarks cannot
// be used (among them, landmarks that look read in the wrong convention,
// unless parameters.checkConvention is off), and for impossible parameters; `progress` (may be empty) sees
// every step. `extraForces` (not owned) act besides the segmentation's own
// (segment() in Segmentation.h), e.g. the other structures' barrier.
SegmentOutcome segmentImage(const Volume& image, const SegmentInputs& inputs, const SegmentParameters& parameters,
                            const ProgressCallback& progress = nullptr,
                            const std::vector<ForceModel*>& extraForces = {});

// report.json's scores against a reference: dice, jaccard, the volume
// difference, the surface distances and both volumes.
Report metricsReport(const OverlapMetrics& metrics);

// How far the structure's tissue was followed past the outermost clicked
// slices where a spring or the pressure then acted (SliceEnds.h), e.g. "10.0
// mm before the first, 4.5 mm after the last (no end seen)"; empty when
// nothing acted past either. A user whose clicks reach the structure's ends
// needs this to know to turn it off.
std::string carriedPastSlices(const SegmentResult& result);

}  // namespace dynsub
