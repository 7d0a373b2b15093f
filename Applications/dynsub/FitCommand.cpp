// dynsub fit: shape recovery from range data (ShapeRecovery.h).
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <CLI/CLI.hpp>

#include "CommandLine.h"
#include "Commands.h"
#include "EarlierRuns.h"
#include "FigureOutputs.h"
#include "dynsub/ClosestPoint.h"
#include "dynsub/Coordinates.h"
#include "dynsub/EnclosingSphere.h"
#include "dynsub/Error.h"
#include "dynsub/FileNames.h"
#include "dynsub/MeshIO.h"
#include "dynsub/ModelOutputs.h"
#include "dynsub/PointCloudIO.h"
#include "dynsub/ScanNoise.h"
#include "dynsub/ShapeRecovery.h"
#include "dynsub/SpringFile.h"
#include "dynsub/SurfaceCoverage.h"
#include "dynsub/SurfaceWriter.h"

namespace dynsub::app {

namespace {

struct FitCommandOptions {
  std::string points;
  std::string out;
  std::string init = "auto";
  int genus = -1;
  std::string noise = "auto";
  std::string refinement = "local";
  bool keepOutliers = false;
  std::string reference;
  FitOptions fit;
  SimulationArguments simulation;
  FigureOptions figures;
};

bool isBuiltInShape(const std::string& init) { return init == "auto" || init == "sphere" || init == "torus"; }

std::string genusProblem(int genus, int asked) {
  return "the initial model has genus " + std::to_string(genus) + " but --genus " + std::to_string(asked) +
         " was asked for" +
         (asked == 0   ? " (use --init sphere)"
          : asked == 1 ? " (use --init torus or a control mesh of genus 1)"
                       : " (give a control mesh of that genus with --init MESH)");
}

// --init's value, checked before the scan is read: a built-in shape's genus
// is known, and a word that names neither a shape nor a mesh file is a typo
// or a `dynsub mesh` name, not a file of an unknown format.
void checkInitialModelOption(const FitCommandOptions& o) {
  if (isBuiltInShape(o.init)) {
    const int genus = o.init == "torus" ? 1 : 0;
    // A built-in shape of the wrong genus is two options that do not fit together.
    if (o.genus >= 0 && genus != o.genus) throw UsageError("--init " + o.init, genusProblem(genus, o.genus));
    return;
  }
  const std::string extension = lowerCaseExtension(o.init);
  std::error_code ignored;
  if (extension.empty() && !std::filesystem::exists(o.init, ignored))
    throw UsageError("--init " + o.init + ": expected auto, sphere, torus or a control mesh file (.obj, .off, .ply)");
}

ControlMesh chooseInitialModel(const FitCommandOptions& o, const MatrixX3& data) {
  ControlMesh mesh;
  const bool shape = isBuiltInShape(o.init);
  if (shape) {
    mesh = initialModel(data, o.init == "torus" ? InitialShape::Torus : InitialShape::Sphere);
  } else {
    mesh = readControlMesh(o.init);
    if (!mesh.isClosed()) {
      throw Error(o.init, "the initial model must be closed, but it has " + std::to_string(mesh.boundaryLoopCount()) +
                              " boundary loop(s)");
    }
    requireOutwardFacing(mesh, o.init);
  }
  // A built-in shape's genus was checked before the scan was read; a mesh
  // file of the wrong genus is that file's problem.
  if (!shape && o.genus >= 0 && mesh.genus() != o.genus) throw Error(o.init, genusProblem(mesh.genus(), o.genus));
  return mesh;
}

// Uncovered surface (SurfaceCoverage.h) beyond this share of its area is
// warned about.
constexpr double kUncoveredWarning = 0.01;
// Points spread over a mesh's faces to measure its coverage against (at
// least one per triangle): the density of a dense scan.
constexpr int kMeshCoverageSamples = 30000;

std::string uncoveredWarning(const SurfaceCoverage& coverage, const std::string& scan, double diameter,
                             bool surfaceSprings) {
  std::ostringstream text;
  text << std::fixed << std::setprecision(1) << 100.0 * coverage.uncoveredFraction
       << " % of the fitted surface's area lies farther than " << std::setprecision(0) << kCoverageSpacings
       << " point spacings plus the max error (" << std::setprecision(3) << coverage.limit << " mm) from " << scan
       << ", up to " << std::setprecision(2) << 100.0 * coverage.maxGap / diameter
       << " % of the diameter away: surface where the scan has none, which the fit's error, measured from the points "
          "to the surface, does not see. It is a web across a gap the model has not followed, a membrane over a hole "
          "the model's genus cannot keep (--init torus, or --init MESH with a closed control mesh of the scan's "
          "genus), or a cap over an opening of an open scan";
  if (!surfaceSprings) text << " (--surface-springs 0.1 pulls webs onto the scan)";
  return text.str();
}

// --noise: "auto", "measure" or a number of mm, 0 to kLargestCoordinate (returned; -1 for the
// others).
double statedNoise(const std::string& text) {
  if (text == "auto" || text == "measure") return -1.0;
  double value = 0.0;
  size_t used = 0;
  try {
    value = std::stod(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  // A length beyond the largest coordinate a scan may have (Coordinates.h).
  if (used != text.size() || !std::isfinite(value) || value < 0.0 || value > kLargestCoordinate) {
    throw CLI::ValidationError("--noise", "expected auto, measure or a number of mm, 0 to 1e9, got '" + text + "'");
  }
  return value;
}

// Surface springs a thousand times the useful 0.1 (their help): beyond it
// they outweigh the data, and the fit drifts from the scan.
constexpr double kLargestSurfaceSprings = 100.0;

void runFit(FitCommandOptions o) {
  const double stated = statedNoise(o.noise);
  checkInitialModelOption(o);
  const std::filesystem::path dir(o.out);
  requireInputsOutsideRun(dir, {o.points, o.reference, o.init});
  const PointCloud input = readPointCloud(o.points);
  const MatrixX3& scan = input.points;
  checkPointCloud(scan, o.points);
  // A noise wider than the scan itself is a slip (a value meant in another
  // unit): the fit would take every point's scatter for noise and stop at once.
  const double extent = (scan.colwise().maxCoeff() - scan.colwise().minCoeff()).norm();
  if (stated > extent) {
    std::ostringstream message;
    message << "--noise " << o.noise << ": more than the whole scan, " << extent << " mm across its bounding box";
    throw UsageError(o.points, message.str());
  }
  const PointCloud referenceCloud = o.reference.empty() ? PointCloud() : readPointCloud(o.reference);
  const MatrixX3& reference = referenceCloud.points;
  if (!o.reference.empty()) checkPointCloud(reference, o.reference);
  // A mesh's vertices are where its maker put the surface: their scatter
  // about their neighbours' quadric is the mesh's own detail, which the fit
  // is asked to follow, and no vertex is an outlier. Taken for noise, that
  // detail would end the fit by the bias rule (ShapeRecovery.h) short of the
  // tolerance.
  const bool exactVertices = input.meshVertices && o.noise == "auto";
  // The scan's own noise and outliers (ScanNoise.h), unless both are stated.
  ScanNoise noise;
  const bool measured = !exactVertices && scan.rows() > kNoiseNeighbours && (stated < 0.0 || !o.keepOutliers);
  if (measured) noise = estimateScanNoise(scan);
  if (stated >= 0.0) noise.sigma = stated;
  if (o.keepOutliers) noise.outliers.clear();
  const MatrixX3 data = withoutRows(scan, noise.outliers);
  // Written beside the results and drawn in the figures: what was set aside
  // is for the user to judge, not only to count.
  const MatrixX3 outliers = scan(noise.outliers, Eigen::all);
  if (data.rows() < 4) throw Error(o.points, "fewer than 4 points are left once the outliers are set aside");
  o.fit.noise = noise.sigma;
  o.fit.localRefinement = o.refinement == "local";
  const ControlMesh initial = chooseInitialModel(o, data);
  const int dataGenus = closedMeshGenus(input, o.points);
  std::vector<std::string> warnings;
  if (dataGenus >= 0 && dataGenus != initial.genus()) {
    const std::string g = std::to_string(dataGenus);
    const std::string builtIn = dataGenus == 0 ? "--init auto or " : dataGenus == 1 ? "--init torus or " : "";
    // A model of lower genus spans the scan's holes with surface its error
    // does not see; one of higher genus keeps holes the scan has not.
    const std::string why = dataGenus > initial.genus()
                                ? "its surface spans the scan's holes, where the fit's error, measured from the points "
                                  "to the surface, does not see it"
                                : "its surface keeps holes the scan has not";
    warnings.push_back(o.points + " is a closed mesh of genus " + g + " but the initial model has genus " +
                       std::to_string(initial.genus()) + ": " + why + " (give " + builtIn +
                       "a closed control mesh of genus " + g + " with --init MESH)");
  }
  // Files of one scene that disagree on the mark end mirrored against each
  // other: the fit's error against the reference would measure the mirror.
  if (!o.reference.empty() && (input.space == "RAS") != (referenceCloud.space == "RAS"))
    warnings.push_back((input.space == "RAS" ? o.points : o.reference) +
                       " is marked SPACE=RAS and was turned to LPS, " +
                       (input.space == "RAS" ? o.reference : o.points) +
                       " is not: if both are in RAS, the reference's errors measure a mirror image (mark both, or "
                       "neither)");
  prepareOutputDirectory(dir);
  o.fit.simulation = o.simulation.apply(o.fit.simulation);
  o.figures.prepare();

  ProgressLine line;
  // The papers' max error every 5 steps: the data springs' lengths where the
  // fit measured them at that state (the static scheme), else the data's
  // nearest points tracked from sample to sample (the report's figures come
  // from a full search at each level's end).
  const double diameter = 2.0 * smallestEnclosingSphere(data).radius;
  TrackedDistances tracked(data);
  ConvergenceRecorder recorder(
      "max error (% of diameter)",
      [&](const Progress& p) {
        const Eigen::VectorXd distances =
            p.dataDistances ? *p.dataDistances : tracked.measure(*p.surface, p.level, *p.controlPoints);
        return 100.0 * distances.maxCoeff() / diameter;
      },
      5);
  const FitResult result =
      naming(o.points, [&] { return fitPointCloud(data, initial, o.fit, recorder.callback(line.callback())); });
  line.finish();
  ConvergenceHistory history = recorder.history();
  for (size_t i = 0; i < result.levels.size(); ++i)
    history.setLevelEndError(result.levels[i].level, result.levelErrors[i].maxPercent);

  const TriangleSurface surface = outputSurface(result.mesh, *result.surface);
  // A mesh's coverage is measured against its faces, a scan's against its points.
  const double maxError = result.error.maxPercent * diameter / 100.0;
  const MatrixX3 faceSamples =
      input.faces.empty() ? MatrixX3() : sampleMeshFaces(scan, input.faces, kMeshCoverageSamples);
  const SurfaceCoverage coverage =
      measureSurfaceCoverage(surface, faceSamples.rows() >= 2 ? faceSamples : data, maxError);
  // A closed mesh of another genus has been warned about already, with its cause.
  if (coverage.uncoveredFraction > kUncoveredWarning && (dataGenus < 0 || dataGenus == initial.genus())) {
    warnings.push_back(uncoveredWarning(coverage, o.points, diameter, o.fit.surfaceSprings > 0.0));
  }
  const std::size_t warned = warnings.size();
  const Report crossing = selfIntersectionReport(surface, "", warnings);
  // The fit's error, the points' distances to the surface, does not see a
  // fold where no point is nearest to it (the ends of a long, thin shape);
  // surface springs pull such surface onto the data. They are not the
  // default: they double the time of a fit that folds a little (the bear's
  // 1.34 % of crossing area becomes 1.07 %).
  if (warnings.size() > warned && o.fit.surfaceSprings == 0.0)
    warnings.back() +=
        " (--surface-springs 0.1 pulls folds where no data point is nearest to the surface onto the data)";

  Report report;
  report.set("input", o.points);
  report.set("input_turned_from_ras", input.space == "RAS");
  report.set("points", data.rows());
  report.set("max_error_percent", result.error.maxPercent);
  report.set("rms_error_percent", result.error.rmsPercent);
  report.set("tolerance_percent", o.fit.tolerancePercent);
  report.set("converged", result.toleranceMet);
  Report noiseReport;
  noiseReport.set("sigma_mm", noise.sigma);
  noiseReport.set("sigma_percent", 100.0 * noise.sigma / diameter);
  noiseReport.set("reach_percent", 100.0 * noiseReach(data.rows()) * noise.sigma / diameter);
  noiseReport.set("estimated", measured && stated < 0.0);
  noiseReport.set("mesh_vertices_exact", exactVertices);
  if (measured) {
    noiseReport.set("scatter_percent", 100.0 * noise.scatter / diameter);
    noiseReport.set("scatter_few_percent", 100.0 * noise.scatterFew / diameter);
  }
  noiseReport.set("outliers", static_cast<int>(noise.outliers.size()));
  if (outliers.rows() > 0) noiseReport.set("outliers_file", kOutliersFile);
  noiseReport.set("noise_limited", result.noiseLimited);
  if (result.noiseLimited) noiseReport.set("bias_percent", result.error.biasPercent);
  report.set("data_noise", noiseReport);
  Report coverageReport;
  coverageReport.set("spacing_mm", coverage.spacing);
  coverageReport.set("max_gap_percent", 100.0 * coverage.maxGap / diameter);
  coverageReport.set("uncovered_area_percent", 100.0 * coverage.uncoveredFraction);
  coverageReport.set("gap_spacings", kCoverageSpacings);
  report.set("surface_coverage", coverageReport);
  report.set("self_intersection", crossing);
  if (!o.reference.empty()) {
    const FitError e = measureFitError(*result.surface, result.mesh.points(), reference, diameter);
    Report against;
    against.set("points", o.reference);
    against.set("turned_from_ras", referenceCloud.space == "RAS");
    against.set("max_error_percent", e.maxPercent);
    against.set("rms_error_percent", e.rmsPercent);
    report.set("reference", against);
  }
  Report sphere;
  sphere.set("center_mm", result.enclosingSphere.center);
  sphere.set("diameter_mm", 2.0 * result.enclosingSphere.radius);
  sphere.set("method", "smallest enclosing sphere (Welzl's algorithm, exact)");
  report.set("enclosing_sphere", sphere);
  report.set("control_vertices", result.mesh.vertexCount());
  report.set("free_control_points", result.levels.back().freeControlPoints);
  report.set("control_faces", result.mesh.faceCount());
  report.set("genus", result.mesh.genus());
  if (dataGenus >= 0) report.set("data_genus", dataGenus);
  report.set("warnings", warnings);
  report.set("levels", result.levels.back().level);
  report.set("iterations", result.steps);
  report.set("seconds", result.seconds);
  std::vector<Report> levels;
  for (size_t i = 0; i < result.levels.size(); ++i) {
    Report level = levelReport(result.levels[i], result.levelErrors[i].maxPercent, result.levelErrors[i].rmsPercent);
    if (result.noiseLimited) level.set("bias_percent", result.levelErrors[i].biasPercent);
    levels.push_back(level);
  }
  report.set("per_level", levels);
  Report parameters = simulationReport(o.fit.simulation);
  parameters.set("init", o.init);
  parameters.set("data_stiffness", o.fit.dataStiffness);
  parameters.set("springs_per_element", o.fit.springsPerElement);
  parameters.set("noise", o.noise);
  parameters.set("keep_outliers", o.keepOutliers);
  parameters.set("to_equilibrium", o.fit.toEquilibrium);
  parameters.set("surface_springs", o.fit.surfaceSprings);
  parameters.set("refinement", o.fit.refinesLocally() ? "local" : "global");
  report.set("parameters", parameters);

  writeModelOutputs(dir, result.mesh, surface, report, [&](OutputSet& outputs) {
    retireEarlierRun(outputs, dir);
    if (outliers.rows() > 0) writePointCloudXyz(outliers, outputs.add(kOutliersFile));
    FigureInputs inputs;
    inputs.surface = &surface;
    inputs.dataPoints = data;
    inputs.outliers = outliers;
    inputs.history = &history;
    // Coloured by the distance to the scan, magenta where uncovered.
    if (coverage.limit > 0.0) {
      inputs.scanDistances = coverage.distances;
      inputs.scanDistanceFar = coverage.limit;
    }
    addFigureOutputs(outputs, o.figures, result.mesh, std::move(inputs));
  }, {{kScanDistanceScalars, coverage.distances, coverage.limit}});

  std::cout << std::fixed << std::setprecision(3) << "fitted " << data.rows() << " points with "
            << result.mesh.vertexCount() << " control vertices";
  if (result.levels.back().freeControlPoints != result.mesh.vertexCount()) {
    std::cout << ", " << result.levels.back().freeControlPoints << " of them free";
  }
  std::cout << " (" << result.levels.back().level << " refinement(s), " << result.steps << " steps) in "
            << std::setprecision(1) << result.seconds << " s\n"
            << std::setprecision(3) << "max error " << result.error.maxPercent << " %, rms error "
            << result.error.rmsPercent << " % of the enclosing sphere's diameter ("
            << 2.0 * result.enclosingSphere.radius << " mm)"
            << (result.toleranceMet ? "" : " -- above the tolerance") << '\n';
  if (result.noiseLimited) {
    std::cout << "the data's noise (sigma " << 100.0 * noise.sigma / diameter
              << " %) puts that tolerance out of reach of the max error; the surface's bias is "
              << result.error.biasPercent << " %\n";
  }
  // Said only where taking the scatter for noise would have changed the fit.
  if (measured && stated < 0.0 && noise.sigma == 0.0 &&
      noiseLimits(data.rows(), noise.scatter, diameter, o.fit.tolerancePercent)) {
    std::cout << "the points' scatter about their neighbours' surface grows from "
              << 100.0 * noise.scatterFew / diameter << " % with " << kNoiseNeighboursFew << " neighbours to "
              << 100.0 * noise.scatter / diameter << " % with " << kNoiseNeighbours
              << ": it is the shape's detail at this sampling, not noise, and the scan was fitted as clean data\n";
  }
  for (const auto& [path, cloud] : {std::pair{&o.points, &input}, std::pair{&o.reference, &referenceCloud}})
    if (cloud->space == "RAS")
      std::cout << *path
                << " is marked SPACE=RAS (3D Slicer's mark): its x and y were negated to LPS, the coordinates of "
                   "the outputs\n";
  if (exactVertices) {
    std::cout << "the points are a mesh's vertices, taken as exact: no noise and no outliers (--noise measure "
                 "measures their scatter)\n";
  }
  if (!noise.outliers.empty())
    std::cout << "set aside " << noise.outliers.size() << " outlier(s), written to " << (dir / kOutliersFile).string()
              << '\n';
  for (const std::string& warning : warnings) std::cerr << "warning: " << warning << '\n';
  std::cout << "wrote " << (dir / kSurfaceFile).string() << ", control_mesh.obj, report.json, convergence.csv"
            << (o.figures.figures ? " and the figures that could be rendered" : "") << '\n';
}

}  // namespace

void addFitCommand(CLI::App& app) {
  auto o = std::make_shared<FitCommandOptions>();
  CLI::App* command = app.add_subcommand(
      "fit",
      "Recover a smooth surface from a point cloud (range data) with a dynamic subdivision surface.\n"
      "Springs pull the limit surface toward the data; at equilibrium the control mesh is refined until the "
      "largest distance from a data point to the surface is below the tolerance (percent of the diameter of "
      "the smallest sphere enclosing the data).\n"
      "Writes DIR/surface.vtp, DIR/control_mesh.obj, DIR/report.json, DIR/convergence.csv and the figures "
      "DIR/slices.png, DIR/surface3d.png and DIR/convergence.png (or .pdf, .svg: --figure-format); and "
      "DIR/outliers.xyz when points were set aside as outliers (the figures draw them in orange).");
  command->add_option("POINTS", o->points, "Point cloud: .xyz/.txt/.pwn, .csv, .ply, .off, .obj or .vtp (mm)")
      ->required();
  command->add_option("--out", o->out, "Output directory (created if missing; its parent must exist)")->required();
  command->add_option("--init", o->init,
                      "Initial model: auto or sphere (the 98-vertex cube inside the data's PCA ellipsoid), torus "
                      "(the 32-vertex torus, for genus 1), or a closed control mesh file of the data's genus")
      ->default_val("auto");
  command->add_option("--genus", o->genus, "Genus the data is known to have; the initial model must match")
      ->check(numberBetween(0, 100, true));
  command->add_option("--tolerance", o->fit.tolerancePercent, "Max error to reach, in percent of the diameter")
      ->default_val(1.0)
      ->check(positiveNumber(100.0));
  command
      ->add_option("--data-stiffness", o->fit.dataStiffness,
                   "Spring stiffness of the data, N/mm per unit parametric area, shared by all points")
      ->default_val(o->fit.dataStiffness)
      ->check(positiveNumber(kLargestSpringStiffness));
  command
      ->add_option("--springs-per-element", o->fit.springsPerElement,
                   "Data springs that pull a level, per element of its surface: a fixed random sample of the "
                   "points, with their total stiffness, where the scan has more (0: every point at every level). "
                   "Each level's fit is measured on all the points")
      ->default_val(o->fit.springsPerElement)
      ->check(nonNegativeNumber());
  command->add_option("--noise", o->noise,
                      "The scan's noise: auto (measured from the points' scatter about their neighbours' local "
                      "surface; a mesh's vertices, read from a file with faces, are taken as exact, with no noise "
                      "and no outliers), measure (measured, for a mesh too) or its standard deviation in mm (0: "
                      "clean data). When the noise puts the tolerance out of reach of the max error, the fit holds "
                      "the surface's bias to it instead")
      ->default_val("auto");
  command->add_flag("--keep-outliers", o->keepOutliers,
                    "Fit every point; by default points far off their neighbours' local surface are set aside "
                    "(written to DIR/outliers.xyz)");
  command
      ->add_option("--refinement", o->refinement,
                   "local: where the fit is refused, a level's faces are refined and their new points move, while "
                   "elsewhere the refined mesh keeps the coarser level's shape and freedom (the written control "
                   "mesh is the refined mesh, with the same limit surface; the static scheme only, the others refine "
                   "globally); global: every face, as the papers do")
      ->default_val("local")
      ->check(CLI::IsMember({"local", "global"}));
  command
      ->add_option("--surface-springs", o->fit.surfaceSprings,
                   "Stiffness of springs from each point of the surface to its nearest data point, relative to the "
                   "data springs' (0: none, the papers' fit). They pull webs and membranes that no data point is "
                   "nearest to onto the scan; 0.1 removed most of those the coverage warning reported on clouds of "
                   "CGAL's meshes, in 0.8-1.5 times the time")
      ->default_val(0.0)
      ->check(nonNegativeNumber(kLargestSurfaceSprings));
  command->add_flag("--to-equilibrium", o->fit.toEquilibrium,
                    "Run the last level on to its equilibrium, as the papers do; by default the fit ends at the "
                    "first step where the tolerance is met");
  command->add_option("--reference", o->reference,
                      "Points the fitted surface is also measured against (say, the scan before noise was added); "
                      "reported as reference in report.json")
      ->check(CLI::ExistingFile);
  o->simulation.addOptions(*command, FitOptions::defaultSimulation());
  command
      ->add_option("--relaxations", o->simulation.values.relaxations,
                   "Times a level whose fit is refused within twice the tolerance is run on with its tension and "
                   "rigidity weakened 4-fold more, before it is refined")
      ->default_val(FitOptions::defaultSimulation().relaxations)
      ->check(numberBetween(0, 6, true));
  o->figures.addOptions(*command);
  command->callback([o] { runFit(*o); });
}

}  // namespace dynsub::app
