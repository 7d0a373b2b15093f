// DynSub's segmentation beside ITK's threshold level set, geodesic active
// contour and deformable simplex mesh, in one run, on the same cropped region
// of the same MRI from the same landmarks:
//   build/bin/SegmentationComparison [--dynsub-only] [--rounds N] [--write-initial MASK]
//                                    [IMAGE LABELS LANDMARKS LABEL]
// (--dynsub-only: DynSub's segmentation and refit alone, then its rounds
// alone, e.g. for profiling; --rounds: the head-to-head below, 7 rounds
// unless given, 0 for none; --write-initial: only write the level set's
// initial mask on DynSub's region of interest, for ItkThresholdLevelSetCommand)
// (defaults: the demo's left caudate of Colin27 against AAL label 71).
// DynSub uses the landmarks as springs; the level set cannot, so it starts
// from DynSub's own initial model (voxelized) and reads its speed image's
// edge level at the landmarks. The simplex mesh starts from the same initial
// model's limit surface (as triangles) and cannot use the landmarks either.
// The threshold level set (ITK-SNAP's region snake) starts from the same
// voxelized model, with its intensity window from the voxels inside it.
// Prints Dice, distances and seconds for each, DynSub's stage seconds, and the
// process's peak memory after each method. Then DynSub's refit after one more
// landmark (what the viewer's worker runs when a click is added after a fit):
// on the reference's lateral edge in the coronal plane y = 16 mm, between the
// demo's landmark slices.
// Last, head to head: DynSub's segmentation and ITK's fastest run above (the
// threshold level set, window mean +- 1 sd, curvature 3) taking turns for N
// rounds, each one's median and range, because one run each on a shared
// virtual machine can vary by half its time.
#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <string>
#include <vector>

#include "BridgeGeometry.h"
#include "ItkDeformableSimplexMesh.h"
#include "ItkGeodesicActiveContour.h"
#include "ItkThresholdLevelSet.h"
#include "dynsub/Error.h"
#include "dynsub/ImageIO.h"
#include "dynsub/LimitSurface.h"
#include "dynsub/Labelmap.h"
#include "dynsub/Metrics.h"
#include "dynsub/Segmentation.h"
#include "dynsub/Tessellation.h"
#include "dynsub/Voxelize.h"

namespace {

using namespace dynsub;

double peakMegabytes() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_maxrss / 1024.0;
}

void printRow(const char* method, const OverlapMetrics& m, double seconds, const std::string& extra) {
  std::printf("%-34s Dice %.3f  Jaccard %.3f  volume %+6.1f %%  MSD %.2f mm  HD95 %.2f mm  %7.2f s  %s\n", method,
              m.dice, m.jaccard, m.volumeDifferencePercent, m.meanSurfaceDistance, m.hd95, seconds, extra.c_str());
}

// The reference's outermost voxel (largest LPS x) in the coronal plane y, plus
// half a voxel: a click on the structure's lateral edge.
Vector3 lateralEdge(const Mask& reference, double y) {
  const ImageGeometry& g = reference.geometry;
  Vector3 edge(-1e300, 0, 0);
  for (int k = 0; k < g.size[2]; ++k)
    for (int j = 0; j < g.size[1]; ++j)
      for (int i = 0; i < g.size[0]; ++i) {
        if (!reference.voxels[g.offset(i, j, k)]) continue;
        const Vector3 p = g.toPhysical(Vector3(i, j, k));
        if (std::abs(p.y() - y) < 0.5 && p.x() > edge.x()) edge = p;
      }
  if (edge.x() < -1e299) throw Error("the reference has no voxel in the coronal plane y = " + std::to_string(y));
  edge.x() += 0.5 * g.spacing.x();
  return edge;
}

void refitAfterOneLandmark(const Volume& image, const Mask& reference, std::vector<Landmark> landmarks,
                           const ControlMesh& initial, const SegmentResult& fitted) {
  const SegmentOptions options;
  const SegmentationRegion region(image, landmarks, initial, options);  // the viewer keeps the first fit's
  landmarks.push_back({"added", lateralEdge(reference, 16.0)});
  const auto started = std::chrono::steady_clock::now();
  const SegmentResult refit = evolveInRegion(region, landmarks, fitted.mesh, fitted.origin, options);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  double worst = 0;
  for (double d : refit.landmarkDistances) worst = std::max(worst, d);
  std::printf("refit after one more landmark: %.3f s, %d steps at %d control vertices (level build and steps %.3f s), "
              "farthest landmark %.2f mm\n",
              seconds, refit.steps, refit.levels.back().controlVertices, refit.levels.back().seconds, worst);
}

// Median, lowest and highest of `seconds` (not empty).
std::string spread(std::vector<double> seconds) {
  std::sort(seconds.begin(), seconds.end());
  char text[96];
  std::snprintf(text, sizeof text, "median %.3f s (%.3f-%.3f)", seconds[seconds.size() / 2], seconds.front(),
                seconds.back());
  return text;
}

int run(int argc, char** argv) {
  const bool dynsubOnly = argc > 1 && std::string(argv[1]) == "--dynsub-only";
  if (dynsubOnly) --argc, ++argv;
  int rounds = 7;
  if (argc > 2 && std::string(argv[1]) == "--rounds") {
    rounds = std::stoi(argv[2]);
    if (rounds < 0 || rounds > 1000) throw Error("--rounds must be in 0..1000, got " + std::string(argv[2]));
    argc -= 2, argv += 2;
  }
  std::string initialPath;  // --write-initial: write the initial mask and stop
  if (argc > 2 && std::string(argv[1]) == "--write-initial") {
    initialPath = argv[2];
    argc -= 2, argv += 2;
  }
  const std::string templates = "/usr/share/mricron/templates/";
  const std::string imagePath = argc > 1 ? argv[1] : templates + "ch2.nii.gz";
  const std::string labelsPath = argc > 2 ? argv[2] : templates + "aal.nii.gz";
  const std::string landmarksPath = argc > 3 ? argv[3] : std::string(DYNSUB_DATA_DIR) + "/Landmarks/caudate_left.mrk.json";
  const int label = argc > 4 ? std::stoi(argv[4]) : 71;

  const Volume image = readVolume(imagePath);
  const Mask reference = selectLabels(readVolume(labelsPath), {label});
  const std::vector<Landmark> landmarks = readLandmarks(landmarksPath);
  const ControlMesh initial = initialFromLandmarks(landmarks);
  std::printf("%s, label %d, %zu landmarks from %s\n", imagePath.c_str(), label, landmarks.size(),
              landmarksPath.c_str());

  const SegmentResult dynsub = segment(image, landmarks, initial, SegmentOptions());
  const auto voxelizing = std::chrono::steady_clock::now();
  const Mask dynsubLabelmap = labelmapOf(dynsub.surface, image.geometry);
  const double voxelizeSeconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - voxelizing).count();
  const double dynsubSeconds = dynsub.seconds.crop + dynsub.seconds.potential + dynsub.seconds.evolution + voxelizeSeconds;
  const double dynsubPeak = peakMegabytes();
  const ImageGeometry region = image.geometry.region(dynsub.regionFirst, dynsub.regionSize);
  std::printf("region of interest %d x %d x %d voxels\n", region.size[0], region.size[1], region.size[2]);

  // The level set on the same region, from the same initial model.
  const Volume cropped = cropVolume(image, dynsub.regionFirst, dynsub.regionSize);
  const LimitSurface surface(initial);
  const TriangleSurface start = tessellate(surface, initial.points(), 8);
  const Mask initialMask = voxelizeSurface(start.points, start.triangles, region);
  if (!initialPath.empty()) {
    writeMask(initialMask, initialPath);
    std::printf("initial mask on the region written to %s\n", initialPath.c_str());
    return 0;
  }
  std::vector<std::array<int, 3>> edgeVoxels;
  for (const Landmark& l : landmarks) {
    const Vector3 index = region.toIndex(l.position);
    edgeVoxels.push_back({static_cast<int>(std::lround(index[0])), static_cast<int>(std::lround(index[1])),
                          static_cast<int>(std::lround(index[2]))});
  }

  printRow("dynsub segment (defaults)", compareMasks(dynsubLabelmap, reference), dynsubSeconds,
           std::to_string(dynsub.levels.back().controlVertices) + " control vertices, peak " +
               std::to_string(static_cast<int>(dynsubPeak)) + " MB");
  std::printf("  stages: crop %.4f s, edge potential %.3f s, evolution %.3f s, voxelize %.3f s\n",
              dynsub.seconds.crop, dynsub.seconds.potential, dynsub.seconds.evolution, voxelizeSeconds);
  // One timed round of DynSub's segmentation and its labelmap, as the
  // command makes them: its seconds and its labelmap.
  // Each round's stages too: crop and edge potential, evolution, labelmap.
  std::vector<double> potentialRounds, evolutionRounds, labelmapRounds;
  auto dynsubRound = [&](std::vector<double>& seconds) {
    const auto started = std::chrono::steady_clock::now();
    const SegmentResult again = segment(image, landmarks, initial, SegmentOptions());
    const auto evolved = std::chrono::steady_clock::now();
    Mask labelmap = labelmapOf(again.surface, image.geometry);
    const auto ended = std::chrono::steady_clock::now();
    seconds.push_back(std::chrono::duration<double>(ended - started).count());
    potentialRounds.push_back(again.seconds.crop + again.seconds.potential);
    evolutionRounds.push_back(again.seconds.evolution);
    labelmapRounds.push_back(std::chrono::duration<double>(ended - evolved).count());
    return labelmap;
  };
  auto printStages = [&] {
    std::printf("  its stages: crop and edge potential %s; evolution %s; labelmap %s\n",
                spread(potentialRounds).c_str(), spread(evolutionRounds).c_str(), spread(labelmapRounds).c_str());
  };
  if (dynsubOnly) {
    refitAfterOneLandmark(image, reference, landmarks, initial, dynsub);
    std::vector<double> seconds;
    for (int r = 0; r < rounds; ++r) dynsubRound(seconds);
    if (rounds > 0) {
      std::printf("dynsub segment alone, %d rounds: %s\n", rounds, spread(seconds).c_str());
      printStages();
    }
    return 0;
  }
  printRow("initial model (both methods)", compareMasks(pasteMask(initialMask, image.geometry, dynsub.regionFirst),
                                                        reference), 0.0, "");
  struct ThresholdRun {
    double window, curvature;
  };
  for (const ThresholdRun& t : std::vector<ThresholdRun>{{0.0, 1.0}, {1.0, 1.0}, {2.0, 1.0}, {0.0, 3.0}, {1.0, 3.0}, {1.5, 3.0}}) {
    const double window = t.window;
    itkbaseline::ThresholdLevelSetOptions options;
    options.window = window;
    options.curvature = t.curvature;
    const itkbaseline::ThresholdLevelSetResult run =
        itkbaseline::thresholdLevelSet(toBridge(region), cropped.voxels, initialMask.voxels, edgeVoxels, options);
    Mask mask{region, run.mask};
    char name[64], extra[128];
    if (window > 0) {
      std::snprintf(name, sizeof name, "ITK threshold LS, %.1f sd, curv. %.0f", window, t.curvature);
    } else {
      std::snprintf(name, sizeof name, "ITK threshold LS, marked, curv. %.0f", t.curvature);
    }
    std::snprintf(extra, sizeof extra, "%d iterations, window %.1f..%.1f, peak %d MB", run.elapsedIterations,
                  run.lower, run.upper, static_cast<int>(peakMegabytes()));
    if (mask.count() == 0) {
      std::printf("%-34s empty result (the front vanished)\n", name);
      continue;
    }
    printRow(name, compareMasks(pasteMask(mask, image.geometry, dynsub.regionFirst), reference), run.seconds, extra);
  }
  for (double propagation : {0.5, 1.0, 2.0}) {
    itkbaseline::GacOptions options;
    options.propagation = propagation;
    const itkbaseline::GacResult gac =
        itkbaseline::geodesicActiveContour(toBridge(region), cropped.voxels, initialMask.voxels, edgeVoxels, options);
    Mask mask{region, gac.mask};
    char name[64], extra[128];
    std::snprintf(name, sizeof name, "ITK GAC, propagation %.1f", propagation);
    std::snprintf(extra, sizeof extra, "%d iterations, sigmoid alpha %.2f beta %.2f, peak %d MB",
                  gac.elapsedIterations, gac.alpha, gac.beta, static_cast<int>(peakMegabytes()));
    if (mask.count() == 0) {
      std::printf("%-34s empty result (the contour vanished)\n", name);
      continue;
    }
    printRow(name, compareMasks(pasteMask(mask, image.geometry, dynsub.regionFirst), reference), gac.seconds, extra);
  }

  // The simplex mesh, in the region's voxel indices (its only frame).
  std::vector<std::array<double, 3>> startIndices;
  for (Eigen::Index p = 0; p < start.points.rows(); ++p) {
    const Vector3 index = region.toIndex(start.points.row(p).transpose());
    startIndices.push_back({index[0], index[1], index[2]});
  }
  struct SimplexRun {
    double beta, kappa;
    int iterations;
  };
  for (const SimplexRun& run : std::vector<SimplexRun>{{0.1, 0, 300}, {0.3, 0, 300}, {0.3, 0.01, 300}, {0.3, 0.02, 300}, {0.3, 0.05, 300}}) {
    itkbaseline::SimplexOptions options;
    options.beta = run.beta;
    options.kappa = run.kappa;
    options.iterations = run.iterations;
    const itkbaseline::SimplexResult simplex =
        itkbaseline::deformableSimplexMesh(toBridge(region), cropped.voxels, startIndices, start.triangles, options);
    MatrixX3 points(simplex.points.size(), 3);
    for (std::size_t p = 0; p < simplex.points.size(); ++p)
      points.row(p) = region.toPhysical(Vector3(simplex.points[p][0], simplex.points[p][1], simplex.points[p][2])).transpose();
    char name[64], extra[128];
    std::snprintf(name, sizeof name, "ITK simplex, beta %.1f, balloon %.2f", run.beta, run.kappa);
    std::snprintf(extra, sizeof extra, "%zu points, peak %d MB", simplex.points.size(),
                  static_cast<int>(peakMegabytes()));
    try {
      const Mask mask = voxelizeSurface(points, simplex.triangles, region);
      printRow(name, compareMasks(pasteMask(mask, image.geometry, dynsub.regionFirst), reference), simplex.seconds,
               extra);
    } catch (const std::exception& e) {
      std::printf("%-34s no closed surface to measure: %s\n", name, e.what());
    }
  }
  refitAfterOneLandmark(image, reference, landmarks, initial, dynsub);

  if (rounds == 0) return 0;
  std::vector<double> dynsubRounds, itkRounds;
  double dynsubDice = 0, itkDice = 0;
  itkbaseline::ThresholdLevelSetOptions fastest;
  fastest.window = 1.0;
  fastest.curvature = 3.0;
  for (int r = 0; r < rounds; ++r) {
    dynsubDice = compareMasks(dynsubRound(dynsubRounds), reference).dice;
    const itkbaseline::ThresholdLevelSetResult itk =
        itkbaseline::thresholdLevelSet(toBridge(region), cropped.voxels, initialMask.voxels, edgeVoxels, fastest);
    itkRounds.push_back(itk.seconds);
    itkDice = compareMasks(pasteMask(Mask{region, itk.mask}, image.geometry, dynsub.regionFirst), reference).dice;
  }
  std::printf("head to head, %d rounds taking turns:\n", rounds);
  std::printf("  dynsub segment (defaults)          Dice %.3f  %s\n", dynsubDice, spread(dynsubRounds).c_str());
  printStages();
  std::printf("  ITK threshold LS, 1.0 sd, curv. 3  Dice %.3f  %s\n", itkDice, spread(itkRounds).c_str());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "SegmentationComparison: %s\n", e.what());
    return 1;
  }
}
