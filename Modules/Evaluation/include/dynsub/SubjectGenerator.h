#pragma once
// Test subjects with exact ground truth, made from one image and its label
// map the way BrainWeb and SynthSeg make theirs: the anatomy is moved by a
// random affine map and a smooth random deformation that cannot fold, and
// the image is then acquired again with a bias field, the scanner's blur,
// thick slices for some subjects and Rician noise at a single scan's SNR.
// The labels move with the anatomy (nearest label), so they stay the
// subject's ground truth.
//
// Two modes give the image its intensities:
// - realistic: the source image itself, moved, with another gamma. Its
//   truth carries whatever disagreement the source label map already had
//   with the source image (for AAL on Colin27, Tools/tissue_ceiling.py
//   measures it).
// - synthesized: an image drawn from labels alone. Each structure's label,
//   and each of three tissue classes that the source's intensities give
//   elsewhere (dark: CSF and bone; grey; white), gets a mean and a texture
//   drawn per subject, in a T1-like or a T2-like order. The structures'
//   edges are then exactly their labels' boundaries, so a score measures
//   edge accuracy with no reference bias.
//
// Everything is drawn from one seed with the standard's Mersenne Twister and
// transforms written here, so a subject is the same on every machine.
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "dynsub/Volume.h"

namespace dynsub {

struct SubjectSettings {
  // The affine part: rotation about each axis up to this angle, scale per
  // axis in 1 +- scaleSpread, shear terms up to shearSpread, translation
  // along each axis up to translationMm.
  double rotationDegrees = 8;
  double scaleSpread = 0.08;
  double shearSpread = 0.04;
  double translationMm = 5;
  // The deformation: a cubic B-spline whose control points, warpSpacingMm
  // apart, move up to warpMm in a random direction. It is one to one
  // (no folding) when warpMm < 0.4 warpSpacingMm (Choi and Lee's bound for
  // cubic B-splines, with margin); larger is refused.
  double warpSpacingMm = 30;
  double warpMm = 5;
  // Where the intensities come from (see above).
  bool synthesized = false;
  // Synthesized subjects: the share drawn with T2-like contrast (white
  // matter darker than grey, CSF brightest); the others are T1-like.
  double t2Fraction = 0;
  // Synthesized subjects: each label's mean lies within +-labelSpread of
  // its tissue's (grey), in units of the source's bright end, so that
  // neighbouring grey structures differ a little, as they do in real scans.
  double labelSpread = 0.05;
  // Synthesized subjects: the labels drawn as structures of their own; the
  // other labels' voxels take their tissue class, as unlabelled ones do.
  // Empty: every label. A parcellation such as AAL labels its cortex far
  // into the white matter, so only its deep structures should be drawn.
  std::vector<int> structureLabels;
  // Realistic subjects: intensities are raised to a gamma of exp(u), u
  // uniform in +-gammaSpread, after scaling the head's intensities to 0..1.
  double gammaSpread = 0.3;
  // A smooth multiplicative bias field within 1 +- biasSpread.
  double biasSpread = 0.15;
  // The scanner's blur: a Gaussian of a sigma drawn in this range (mm).
  std::array<double, 2> blurMm{0.3, 0.7};
  // White matter's signal over the noise's sigma, drawn in this range; the
  // noise added accounts for the source's own (sourceSnr: Colin27, the
  // average of 27 scans, has about 70).
  std::array<double, 2> snr{20, 30};
  double sourceSnr = 70;
  // The share of subjects acquired in thick slices (thickMm along one axis,
  // drawn among the three unless thickAxis names it: 0, 1 or 2, the image's
  // index axes; the labels stay on the fine grid). A named axis is still
  // drawn for, so that it changes nothing else of the subject.
  double thickFraction = 0;
  double thickMm = 3;
  int thickAxis = -1;
};

// What was drawn for one subject (for its record and the report's groups).
struct SubjectDraw {
  std::uint64_t seed = 0;
  std::string contrast = "source";  // realistic: "source"; synthesized: "t1" or "t2"
  double gamma = 1, blurMm = 0, snr = 0, noiseSigma = 0, whiteMatter = 0;
  std::optional<int> thickAxis;  // the axis acquired in thick slices, if any
  double smallestJacobian = 1;   // of the whole map, over the subject's grid
};

struct Subject {
  Volume image;   // the acquired image (float)
  Volume labels;  // the label map on the fine grid, the image's ground truth
  SubjectDraw draw;
};

// The settings by name, as plans and `dynsub subject --set` give them:
// mode ("realistic" or "synthesized"), t2_fraction, label_spread,
// structure_labels ("71,72,..."),
// rotation_degrees, scale_spread, shear_spread, translation_mm,
// warp_spacing_mm, warp_mm, gamma_spread, bias_spread, blur_mm (a range,
// "LOW,HIGH" or one number), snr (a range), source_snr, thick_fraction,
// thick_mm and thick_axis. Throws dynsub::Error naming the key for an
// unknown key or a value that is not a number.
void setSubjectSetting(SubjectSettings& settings, const std::string& key, const std::string& value);

// Throws dynsub::Error for impossible settings (naming the setting).
void checkSubjectSettings(const SubjectSettings& settings);

// What the image and the label map a subject is made from are called in
// its errors: their files, when they come from files.
struct SubjectSources {
  std::string image = "the source image", labels = "the label map";
};

// One subject from `image` and `labels` (any grids that overlap in physical
// space), on `image`'s grid; deterministic in `seed`. The anatomy's map
// depends only on the seed and the map's settings, so a realistic and a
// synthesized subject of one seed share their anatomy. Throws dynsub::Error
// naming the source at fault for an image or label map no subject can be
// made from.
Subject makeSubject(const Volume& image, const Volume& labels, const SubjectSettings& settings, std::uint64_t seed,
                    const SubjectSources& sources = {});

// The record of a draw as JSON text (one object), for subject.json.
std::string subjectRecord(const SubjectDraw& draw);

}  // namespace dynsub
