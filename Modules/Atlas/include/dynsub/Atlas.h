#pragma once
// An atlas's structure carried to a subject, to start a segmentation from
// and to hold it where the image and the clicks say nothing (automatic
// initialization, which the TVCG paper leaves as future work).
//
// The atlas is a template image and its label map on one grid. ITK registers
// the template to the subject in two steps: an affine transform on the whole
// head, maximizing Mattes mutual information (so a T1 template serves a
// subject of another contrast or bias), then a smooth displacement field in
// the structure's neighbourhood. The structure's labels are carried to the
// subject's grid through both; its boundary gives segment() a start and a
// prior (SegmentImage.h).
//
// One affine registration serves every structure of a subject (evaluations
// and several structures reuse it); the displacement field is the structure's own.
#include <array>
#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "dynsub/Landmarks.h"
#include "dynsub/Volume.h"

namespace dynsub {

// Colin27 and the AAL labels, from Debian's mricron-data.
inline const char* const kDefaultAtlasImage = "/usr/share/mricron/templates/ch2.nii.gz";
inline const char* const kDefaultAtlasLabels = "/usr/share/mricron/templates/aal.nii.gz";

// A label map's names (value, name), from the first table beside it that
// exists: for labels.nii.gz, labels.nii.txt or labels.txt, one "VALUE NAME
// ..." per line (mricron's, ITK-SNAP's and FreeSurfer's tables), or
// labels.tsv with the columns `index` and `name` (a BIDS dseg.tsv; a .tsv
// without them is not taken for one). Empty when there is none; throws
// dynsub::Error naming the table for a line it cannot read.
using LabelNames = std::vector<std::pair<int, std::string>>;
LabelNames readLabelNames(const std::string& labelsPath);

// The label values of `spec`, "73", "73,75", "Putamen_L" or
// "Putamen_L,Pallidum_L", in the label map at `labelsPath`: each item a
// number (whatever parseNumber reads as a finite number) or a name in the
// table `names()` gives, which is asked for only when an item is a name (a
// caller can read it then, and once). Throws dynsub::UsageError for an empty
// spec or item, label 0, a value that is not a label, and a name several
// labels share; dynsub::Error naming the map for a name its table does not
// hold (naming the nearest) or a map with no table. `option` is the flag the
// spec came from, for messages.
std::vector<int> labelSpecValues(const std::string& spec, const std::string& labelsPath,
                                 const std::function<const LabelNames&()>& names, const std::string& option);

struct Atlas {
  std::string imagePath, labelsPath;
  Volume image;
  Volume labels;     // on the image's grid
  LabelNames names;  // readLabelNames(labelsPath)
};

// Throws dynsub::Error naming the file when either cannot be read, or when
// the label map is not on the template's grid.
Atlas readAtlas(const std::string& imagePath, const std::string& labelsPath);

// "73", "73,75", "Putamen_L" or "Putamen_L,Pallidum_L": the label values.
// Throws dynsub::Error for a name the table does not hold (naming the
// nearest), or a value no voxel of the label map has; dynsub::UsageError for
// a malformed spec, label 0, a name that matches several labels, and several
// labels that lie in separate pieces (one surface cannot hold them). `option`
// is the flag the spec came from, for messages.
std::vector<int> atlasLabelValues(const Atlas& atlas, const std::string& spec,
                                  const std::string& option = "--atlas-label");

// What a structure given as `spec`, of label values `values`
// (atlasLabelValues's), is called: the table's name when it is one value the
// table names ("73": Putamen_L), else `spec` itself.
std::string atlasStructureName(const Atlas& atlas, const std::vector<int>& values, const std::string& spec);

// y = linear x + translation: a subject point (LPS mm) to the template's.
struct AffineMap {
  Matrix3 linear = Matrix3::Identity();
  Vector3 translation = Vector3::Zero();

  Vector3 operator()(const Vector3& x) const { return linear * x + translation; }
  AffineMap inverse() const;
};

struct AtlasRegistrationOptions {
  // The affine step: the pyramid's voxel sizes (mm), coarse to fine, its
  // iterations per level, and the share of the voxels its metric samples
  // (at random, from a fixed seed).
  std::vector<double> affineLevelsMm{4.0, 2.0};
  int affineIterations = 200;
  double samplingFraction = 0.2;
  // The deformable step: a displacement field over the structure's
  // neighbourhood (its box grown by marginMm) on a grid of this voxel size
  // (coarser for a structure larger than a caudate or a thalamus, so that
  // the field has at most 40,000 voxels), its iterations, and the Gaussian
  // smoothing (sigma, mm) of each step's update and of the whole field.
  double deformableLevelMm = 2.0;
  int deformableIterations = 50;
  double updateSigmaMm = 4.0;
  double totalSigmaMm = 2.0;
  double marginMm = 10.0;
};

void checkAtlasRegistrationOptions(const AtlasRegistrationOptions& options);

struct AtlasAffine {
  AffineMap map;  // subject -> template
  double metric = 0;  // Mattes mutual information at the end (lower is better)
  int iterations = 0;
  double seconds = 0;
};

// Throws dynsub::Error when the registration fails or ends in a degenerate map.
AtlasAffine registerAtlasAffine(const Volume& subject, const Atlas& atlas, const AtlasRegistrationOptions& options);

struct CarriedLabel {
  Mask mask;                   // on a sub-grid of the subject (ImageGeometry::region)
  std::array<int, 3> first{};  // the sub-grid's first voxel in the subject
  double metric = 0;           // the deformable step's mutual information
  int iterations = 0;
  double seconds = 0;          // the deformable step and the carrying
  // The correction an inside click made (mm): how far the label was moved so
  // that the click lies inside it; zero without a click or when it already did.
  Vector3 shift = Vector3::Zero();
  // The field's largest displacement (mm, in the subject, before the
  // affine map): how much the deformable step changed.
  double largestWarpMm = 0;
};

// The structure's labels on the subject's grid, through the affine map and
// a displacement field computed around the structure. With `inside` (a click inside
// the structure, LPS mm): only the carried label's part that holds the
// click, or, when the click lies outside it, the label moved so that the
// click lies 2 mm deep. Throws dynsub::Error when the labels leave nothing on
// the subject's grid, or the click lies outside the image.
CarriedLabel carryLabel(const Volume& subject, const Atlas& atlas, const std::vector<int>& labels,
                        const AtlasAffine& affine, const std::optional<Vector3>& inside,
                        const AtlasRegistrationOptions& options);

// At most `count` points on the carried label's boundary, spread evenly
// (farthest-point sampling), as soft landmarks named "atlas N".
std::vector<Landmark> carriedBoundary(const CarriedLabel& label, int count);

// The carried label's volume (mm^3).
double carriedVolume(const CarriedLabel& label);

}  // namespace dynsub
