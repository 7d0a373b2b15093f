#pragma once
// Whether boundary points were read in the convention they were written in.
// RAS values in a file that says LPS (or in a CSV, which is LPS) put every
// point at (-x, -y, z) of where it was placed; the mirror region is then
// segmented, and nothing else in the run looks wrong. Points placed on a
// structure's boundary lie on image edges that face along the structure's
// normal, and the same points negated often do not, so the edges at the
// points as read are compared with the edges at their two likely
// misreadings:
//  - flipped: x and y negated (RAS read as LPS, or LPS as RAS);
//  - mirrored: x alone negated (left and right swapped).
// A misreading is named when its edges are much stronger or much better
// aligned with the points' shape than the points' own, or both. Where a misreading
// lands on tissue like the structure's (a left-right twin), the image cannot
// tell, and nothing is named.
#include "dynsub/Types.h"
#include "dynsub/Volume.h"

namespace dynsub {

// The edges at one reading of the points: the median over them of the
// strongest gradient magnitude within `reach` mm (strongestVoxelNear, on the
// image smoothed by a Gaussian of `sigma` mm; intensity per mm), and the mean
// alignment (|cos|, 0 to 1) of that gradient with the normal of the points'
// PCA ellipsoid. Both zero for a reading that puts a point outside the image.
struct ReadingEdges {
  double strength = 0;
  double alignment = 0;
};

struct ConventionScores {
  ReadingEdges asRead;
  ReadingEdges flipped;   // x and y negated
  ReadingEdges mirrored;  // x negated
};

enum class Misreading { None, Flipped, Mirrored };

// Throws dynsub::Error for fewer than 4 points (too few for a median to
// mean anything) or an impossible sigma or reach.
ConventionScores conventionScores(const Volume& image, const MatrixX3& points, double sigma, double reach);

// The evidence that a misreading is the points' true place rather than the
// reading as given: ln(its strength / theirs) + kAlignmentWeight x (its
// alignment - theirs), each strength plus a hundredth of the largest of the
// three (flat tissue has a gradient near zero, and the ratio of two near-zero
// gradients says nothing). A misreading is named at kMisreadingEvidence or
// more. The largest evidence a correct click set gave was 1.72 on the
// generated tuning subjects and 1.71 on Colin27 (Segmentation.md, "Points
// read in the wrong convention"): refusing correct points costs a user more
// than the misread ones this bar lets through. Strength alone does not
// separate them: a putamen's or a thalamus's faint boundary can be a third as
// strong as the edges at its flip.
constexpr double kAlignmentWeight = 8.0;
constexpr double kMisreadingEvidence = 2.0;

// Zero for Misreading::None.
double misreadingEvidence(const ConventionScores& scores, Misreading misreading);

// The misreading with evidence kMisreadingEvidence or more, the stronger
// evidence if both have it; None otherwise. A reading with a point outside
// the image is never named.
Misreading likelyMisreading(const ConventionScores& scores);

// The points as a misreading reads them: (-x, -y, z) or (-x, y, z).
MatrixX3 misread(const MatrixX3& points, Misreading misreading);

}  // namespace dynsub
