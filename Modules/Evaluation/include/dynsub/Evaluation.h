#pragma once
// How well segmentation holds up over structures x click protocols x seeds
// (`dynsub evaluate`): each run makes an expert-like landmark set from a
// reference labelmap (ClickProtocol.h), writes it in the protocol's file
// format and reads it back as a user's file would be, segments the image
// (with `dynsub segment`'s defaults unless the plan sets some), and scores
// the result against the reference.
//
// Scoring is in physical space: the final surface is voxelized on the
// reference's own grid, so images of any resolution (Colin27 at 1 mm and at
// 0.5 mm against the 1 mm AAL atlas) are scored alike. Besides Dice and the
// surface distances, a run reports its leak (volume outside the reference)
// and miss (reference volume not covered), and is flagged as a collapse when
// it keeps less than a fifth of the reference's volume.
//
// Plans are JSON (Data/Evaluation/README.md gives the format). A plan's
// splits name which structures and seeds each split runs: the tuning split is
// what parameters may be chosen on, the test split what is reported.
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "dynsub/Atlas.h"
#include "dynsub/ClickProtocol.h"
#include "dynsub/LandmarkConvention.h"
#include "dynsub/SegmentParameters.h"
#include "dynsub/SubjectGenerator.h"
#include "dynsub/Trust.h"

namespace dynsub {

struct EvaluationImage {
  std::string name;
  std::string path;
};

// Generated subjects (SubjectGenerator.h) made from one image and its label
// map, each its own ground truth: a cohort's subjects run in their split only,
// so tuning and test subjects never meet.
struct EvaluationCohort {
  std::string name;
  std::string image, labels;  // paths
  SubjectSettings settings;
  std::vector<std::pair<std::string, std::vector<std::uint64_t>>> subjects;  // split -> subject seeds
};

struct EvaluationStructure {
  std::string name;
  std::vector<int> labels;  // its label values in the reference
  int axis = 1;             // the slice orientation experts use for it
};

struct EvaluationProtocol {
  ClickProtocol clicks;   // its axis is the structure's unless `ownAxis`
  bool ownAxis = false;
  std::string format = "mrk.json";  // mrk.json, fcsv or csv; "rotate": by seed
  // An atlas start (segment --init atlas) with the structure's labels in the
  // plan's atlas: with the clicks as landmarks, with a seed-only protocol's
  // click as --inside, or with no click at all (`noClicks`). Never run on
  // an image that is the atlas's own template: registering it to itself
  // measures nothing.
  bool atlas = false;
  bool noClicks = false;
};

struct EvaluationSplit {
  std::string name;
  std::vector<std::string> structures;  // empty: all
  std::vector<unsigned> seeds;
};

struct EvaluationPlan {
  std::string path;  // the plan's file, for messages
  // What every run segments with: the defaults unless the plan's "segment"
  // object sets some (for comparing settings on the tuning split).
  SegmentParameters parameters;
  std::string reference;  // labelmap path
  std::vector<EvaluationImage> images;
  std::vector<EvaluationCohort> cohorts;
  std::vector<EvaluationStructure> structures;
  std::vector<EvaluationProtocol> protocols;
  std::vector<EvaluationSplit> splits;
  // The atlas of atlas protocols: template and label map, whose label values
  // are the structures' (a cohort generated from it, or an image labelled
  // like it).
  std::string atlasImage = kDefaultAtlasImage, atlasLabels = kDefaultAtlasLabels;
};

// Throws dynsub::Error naming the file and the problem.
EvaluationPlan readEvaluationPlan(const std::string& path);

struct EvaluationRun {
  std::string split, image, structure, protocol, format;
  std::string subject;  // a cohort's subject ("s" and its seed), empty for a plan's image
  double subjectSnr = 0;  // what the subject was drawn with (0 for a plan's image)
  int subjectThickAxis = -1;
  std::string subjectContrast;  // "source", "t1" or "t2" (empty for a plan's image)
  unsigned seed = 0;
  int landmarks = 0;
  std::string error;  // empty when the run succeeded
  double dice = 0, jaccard = 0, meanSurfaceDistance = 0, hd95 = 0;  // distances NaN for an empty result
  double volume = 0, referenceVolume = 0;  // mm^3
  double leak = 0, miss = 0;                // mm^3 outside the reference, reference not covered
  bool collapsed = false;
  // segment()'s share of the surface within a voxel of an edge (what its
  // report calls surface_on_edges), to see how far that trust measure
  // follows the accuracy the reference gives.
  double surfaceOnEdges = 0;
  // The edges at the landmarks as read, flipped and mirrored
  // (LandmarkConvention.h), with 4 or more landmarks.
  std::optional<ConventionScores> convention;
  std::string warnings;  // segment()'s own (collapse, leak), joined by "; "
  TrustMeasures trust;     // the result against what it rests on (Trust.h)
  std::string trustFlags;  // the flags' names, joined by " "
  double seconds = 0;  // segmentImage()'s own (the image is read once per plan, the clicks made before)
  int steps = 0, controlVertices = 0;
};

struct EvaluationOptions {
  std::vector<std::string> splits;  // empty: every split
  int jobs = 2;                     // runs at once
  std::string landmarkDirectory;    // where each run's landmark file is written
};

// The runs of the plan's splits, in a fixed order (split, image or cohort and
// its subjects, structure, protocol, seed) whatever `jobs` is. `done` (may be null) is called after
// each run, from the worker that ran it, serialized.
std::vector<EvaluationRun> runEvaluation(const EvaluationPlan& plan, const EvaluationOptions& options,
                                         const std::function<void(const EvaluationRun&, int finished, int total)>& done);

}  // namespace dynsub
