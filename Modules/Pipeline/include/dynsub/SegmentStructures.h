#pragma once
// Several structures of one image segmented together, so that they do not
// overlap and come out as one labelmap with names (a BIDS dseg):
//  1. each structure is segmented alone (segmentImage);
//  2. the voxels two or more of them claim go to the claimant with the
//     nearest landmark: a surface near its springs is held there by the
//     expert's evidence, one far from them only by its smoothness and the
//     image. This splits the image into territories;
//  3. each structure that shared voxels evolves again, with the others'
//     territories as a barrier: a force that pushes its surface out of them,
//     in proportion to how deep it went (SegmentParameters::barrierStiffness).
//     It resumes from its first surface and levels (segment()'s `resume`),
//     already at equilibrium with its clicks and edges, so that the barrier
//     moves it near the wall and the rest stays as its run alone left it;
//  4. the labelmaps are joined as in 2, so that no voxel has two structures.
// A shared boundary with no edge on it (putamen and pallidum on a T1) is then
// where the two structures meet, not wherever each alone stopped. Each
// structure keeps its own surface and labelmap; the joined labelmap is the
// one without overlap.
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "dynsub/SegmentImage.h"

namespace dynsub {

struct StructureInputs {
  std::string name;  // its name in dseg.tsv and its output folder (isNameCharacter's)
  SegmentInputs inputs;
};

// The characters a structure's name may hold, as it names a folder: letters,
// digits, '_', '-' and '.'.
bool isNameCharacter(char c);
// Whether `name` can name a structure and its folder: isNameCharacter's
// only, and neither empty, "." nor "..".
bool usableStructureName(const std::string& name);

// The colour structure `index` (0-based) is shown in (red, green, blue, 0-255):
// a qualitative palette of ten that neighbours tell apart, repeated past ten.
// dseg.tsv and 3D Slicer segmentations give it.
std::array<std::uint8_t, 3> structureColor(std::size_t index);

struct StructuresOutcome {
  // In the inputs' order; a structure segmented again holds its second
  // segmentation (the one with the barrier) and that segmentation's report.
  std::vector<SegmentOutcome> structures;
  std::vector<bool> segmentedAgain;
  // The joined labelmap on the labelmaps' grid: 0 outside every structure,
  // i + 1 in structure i.
  Volume labels;
  // Against each structure's reference, when given (default metrics
  // otherwise): its first segmentation alone, and its share of `labels`.
  std::vector<OverlapMetrics> aloneMetrics, jointMetrics;
  // Voxels in two or more labelmaps: after step 1, and after step 3 (before
  // the join removes them).
  long long sharedAlone = 0, sharedTogether = 0;
  // The image's affine registrations to an atlas that were made: one per
  // atlas the structures start from (the first structure's serves the others,
  // and a structure segmented again keeps its own).
  int atlasRegistrations = 0;
  double seconds = 0;
  Report report;  // the whole run's: the structures, the overlaps, the scores
};

// The label of each voxel (0: none): the structure (i + 1 for masks[i], all
// on one grid) that holds it or, of several that do, the one with the
// nearest of its points (evidence[i], mm: its landmarks); ties go to the
// earlier mask. Throws dynsub::Error for no masks or masks on different grids.
Volume jointLabels(const std::vector<Mask>& masks, const std::vector<MatrixX3>& evidence);

// Throws dynsub::Error for fewer than two structures, names that are empty,
// repeated or not usable as a folder's name, and whatever segmentImage
// throws for one structure (its message names the structure).
void checkStructures(const std::vector<StructureInputs>& structures, const SegmentParameters& parameters);

StructuresOutcome segmentStructures(const Volume& image, const std::vector<StructureInputs>& structures,
                                    const SegmentParameters& parameters, const ProgressCallback& progress = nullptr);

}  // namespace dynsub
