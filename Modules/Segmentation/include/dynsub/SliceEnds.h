#pragma once
// Landmarks placed on slices leave a structure's ends unclicked: experts
// seldom click its first and last few slices. With no force there, the
// surface's tension pulls it back to the outermost clicked slice, whatever
// it started from. This looks for where the structure ends beyond them and
// puts a soft spring there, at each end:
//  1. The slices: the image axis along which the landmarks take the fewest
//     distinct positions (at least 2, at most a third of the landmarks),
//     each within kOnSliceVoxels; landmarks that are not on slices of the
//     image get no springs.
//  2. Appearance: the median m and robust spread s (1.4826 MAD) of the
//     intensities inside the initial model.
//  3. At each end, from the centroid of the outermost slice's landmarks
//     (at least 3 of them), a march outward along the slice axis in steps
//     of half a voxel: at each step the median intensity of a disk across
//     the axis (radius `disk` times the landmarks' rms distance from their
//     centroid, at least one voxel). The march stops where that median has
//     left c +- window s for two steps running, at most `reach` times the
//     clicked span beyond the slice. c is m moved `endLevel` of the way to
//     the end's own level e, the median of the disks on the end slice and
//     the two steps inward from it (where e lies within m +- window s; else
//     c is m). Where e is not within the window and the march stopped
//     within `gap`, the centroid may lie in other tissue that the section
//     wraps around: the march is made again from a point toward a click
//     whose e is (SliceEnd::marchStart). A structure's intensity drifts
//     along it (a putamen's head is darker than its middle): a window about
//     the whole structure's median can hold the tissue past a dark end, or
//     leave out the end itself.
//     Where the march reaches its limit without leaving the window (no end
//     seen), it marches again with c moved `endLevelAtReach` of the way to
//     e: a window about the whole structure's median that holds the tissue
//     past an end darker than the rest (a putamen's head) is the commonest
//     reason for seeing none.
//     Experts leave some 10-20 % of a structure unclicked at each end, but
//     the clicked span is shorter than the slices' coverage: three slices
//     over 60 % of a caudate span 40 % of it, and its head reaches a
//     clicked span beyond the last one.
//  4. Where the march went more than `gap` mm and stopped at a change of
//     intensity (not at its reach, where it found no end: the structure may
//     go on in like tissue, as a cerebellar hemisphere does across the
//     midline), a spring of `stiffness` pulls the surface to its last step
//     inside; with `taper`, unless the clicked cross-sections widen fast
//     toward the end (kTaperWidening), the end slice's clicks are also
//     copied halfway there, drawn in toward their centroid by sqrt(3/4) as
//     an ellipsoid's cross-section narrows, as springs. Where they widen
//     fast (a caudate's head), no such springs: the structure keeps its width
//     past the end slice, and the pressure of step 5 carries the surface there.
//  5. Beyond the outermost slices, a pressure along the normal from the
//     appearance the clicks taught (ClickAppearance.h's EndPressure),
//     `pressure` N/mm^2 at full strength, within the end slice's footprint:
//     it carries the surface to the structure's own boundary where only the
//     tip and taper springs held it (a caudate's blunt head, a hemisphere's
//     lateral ends). Not beyond an end whose march stopped within `gap` of
//     the slice: the clicks already reach that end. Beyond a tapered end no
//     farther than its march went: the end is where the march saw it.
// A march through the structure's own tissue is what a one-dimensional
// region growth from the clicked end sees; it cannot leak sideways into
// like tissue the way a grown volume does.
#include <string>
#include <vector>

#include "dynsub/ControlMesh.h"
#include "dynsub/Landmarks.h"
#include "dynsub/Volume.h"

namespace dynsub {

// Landmarks this close along an axis (voxels) share a slice.
constexpr double kOnSliceVoxels = 0.25;

// Step 4's taper springs go to an end unless its slice's clicks have an rms
// radius more than this times the next slice's: a structure widening that
// fast at its last clicked slice (a caudate's head) is still far from its
// widest there, and an ellipsoid's taper pulls it in. Chosen on the tuning
// subjects of both generated groups; at 1.0 the putamina, which widen slowly
// toward an end near their widest, lose their taper (Documentation/Segmentation.md).
constexpr double kTaperWidening = 1.3;

// The defaults were chosen on the evaluation plan's tuning split
// (Documentation/Segmentation.md).
struct SliceEndOptions {
  bool enabled = true;
  double window = 2.5;      // robust spreads either side of the median
  double disk = 0.3;        // the disk's radius, a fraction of the end slice's rms radius
  double reach = 1.0;       // the march's longest, a fraction of the clicked span
  double gap = 2.0;         // mm: no spring for a shorter march
  double stiffness = 10.0;  // N/mm per spring
  bool taper = true;        // springs halfway, the end slice's clicks drawn in (unless widening fast)
  bool springAtReach = false;  // a spring also where the march ended at its reach, not at an intensity change
  double pressure = 0.2;       // N/mm^2 beyond the end slices (step 5; 0: none), chosen on the tuning split
  // Step 3: how far the window's centre moves to the end's own level, 0-1.
  // 0, because 0.5 carries the bundled caudate's first march from 2 to 2.5 mm,
  // past `gap`, to an end its clicks reach, and its Dice below the 0.85 that
  // Colin27's rows are held to (Documentation/Segmentation.md).
  double endLevel = 0;
  // Step 3's second march, where the first saw no end: how far its window's
  // centre moves to the end's own level (no second march when it equals
  // endLevel). Chosen on the tuning subjects of the three generated groups
  // (Documentation/Segmentation.md). An end the first march found is kept.
  double endLevelAtReach = 1.0;
};

struct SliceEnd {
  int side = 1;                     // -1: towards lower indices along the axis, +1: higher
  Vector3 start = Vector3::Zero();  // the outermost slice's centroid (LPS mm)
  Vector3 marchStart = Vector3::Zero();  // where the march began: the centroid, or a point toward a click (step 3)
  double sliceRadius = 0;           // mm: that slice's farthest click from the centroid, across the axis
  Vector3 end = Vector3::Zero();    // the march's last step inside
  double low = 0, high = 0;         // the intensities the march followed (step 3)
  double length = 0;                // mm
  bool stoppedByReach = false;      // the intensity never left the window
  bool marchedAgain = false;        // the first march saw no end; the second's window is about the end's level
  bool sprung = false;              // step 4 put springs at this end (it went more than `gap`)
  bool widening = false;            // the end slice's clicks are kTaperWidening times as wide as the next's
  bool tapered = false;             // step 4 also put taper springs here (sprung, `taper`, not widening)
  bool pressed = false;             // step 5's pressure acts beyond this end (set by segment())
  double pressureReach = 0;         // mm: how far beyond the slice it acts (set by segment())
};

struct SliceEnds {
  int axis = -1;  // the image axis of the slices; -1 when the landmarks are not on slices
  int slices = 0;
  double median = 0, spread = 0;
  std::vector<SliceEnd> ends;     // the ends marched from (0, 1 or 2)
  std::vector<Landmark> springs;  // for each end that went more than `gap`: its tip (and taper)
  // Step 5, filled by segment(): the pressure used, the samples and the
  // classes' separation. 0 when off, when the landmarks are not on slices,
  // when every end's march stopped within `gap` (the clicks reach both
  // ends, as the bundled caudate's do), or when the clicks gave too few samples.
  double pressure = 0;
  int insideSamples = 0, outsideSamples = 0;
  double separation = 0;
};

void checkSliceEndOptions(const SliceEndOptions& options);

// Throws dynsub::Error on impossible options. Returns no springs (axis -1)
// for fewer than 4 landmarks or landmarks not on slices.
SliceEnds findSliceEnds(const Volume& image, const std::vector<Landmark>& landmarks, const ControlMesh& initial,
                        const SliceEndOptions& options);

}  // namespace dynsub
