#include "dynsub/SegmentStructures.h"

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <limits>
#include <set>

#include "dynsub/Error.h"
#include "dynsub/ForceModel.h"
#include "dynsub/ImageFilters.h"

namespace dynsub {

bool isNameCharacter(char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.'; }

bool usableStructureName(const std::string& name) {
  if (name.empty() || name == "." || name == "..") return false;
  return std::all_of(name.begin(), name.end(), isNameCharacter);
}

std::array<std::uint8_t, 3> structureColor(std::size_t index) {
  static const std::array<std::uint8_t, 3> palette[] = {
      {0x4e, 0x79, 0xa7}, {0xf2, 0x8e, 0x2b}, {0xe1, 0x57, 0x59}, {0x76, 0xb7, 0xb2}, {0x59, 0xa1, 0x4f},
      {0xed, 0xc9, 0x48}, {0xb0, 0x7a, 0xa1}, {0xff, 0x9d, 0xa7}, {0x9c, 0x75, 0x5f}, {0xba, 0xb0, 0xac}};
  return palette[index % 10];
}

namespace {

// The margin (voxels) around the structures' voxels that the territories,
// and so the barrier, cover: a surface pushed out of a territory, or one
// that swells past its first segmentation, still meets the wall there.
constexpr int kTerritoryMargin = 8;

// A force density that pushes a surface out of a wall (the other structures'
// territories): k times the depth past the wall's boundary, along the
// direction out of it, and nothing outside the wall. The depth is the signed
// distance between voxel centres, d(to the wall) - d(to outside the wall),
// interpolated: -1 voxel on the wall's outer voxels, +1 on their outside
// neighbours, so its zero lies midway, where a labelmap's boundary lies.
class WallForce final : public ForceField {
 public:
  WallForce(const Mask& wall, double stiffness) : geometry_(wall.geometry), stiffness_(stiffness) {
    Mask outside = wall;
    for (std::uint8_t& v : outside.voxels) v = !v;
    const std::vector<float> toWall = distanceTo(wall), toOutside = distanceTo(outside);
    signed_.geometry = geometry_;
    signed_.voxels.resize(toWall.size());
    for (std::size_t i = 0; i < toWall.size(); ++i) signed_.voxels[i] = toWall[i] - toOutside[i];
    toIndex_ = geometry_.indexFromPhysical();
    step_ = 0.5 * geometry_.spacing.minCoeff();
  }

  MatrixX3 forcesAt(const MatrixX3& points) const override {
    MatrixX3 forces = MatrixX3::Zero(points.rows(), 3);
    for (Eigen::Index i = 0; i < points.rows(); ++i) {
      const Vector3 p = points.row(i).transpose();
      const Vector3 index = indexOf(p);
      if (!geometry_.spans(index)) continue;  // beyond the territories' box: no wall there
      const double depth = -signed_.interpolate(index);
      if (depth <= 0) continue;
      Vector3 out;
      for (int a = 0; a < 3; ++a) {
        Vector3 h = Vector3::Zero();
        h(a) = step_;
        out(a) = signed_.interpolate(indexOf(p + h)) - signed_.interpolate(indexOf(p - h));
      }
      const double norm = out.norm();
      if (norm > 0) forces.row(i) = (stiffness_ * depth / norm) * out.transpose();
    }
    return forces;
  }

  double slopeBound() const override { return stiffness_; }

 private:
  Vector3 indexOf(const Vector3& p) const { return toIndex_ * (p - geometry_.origin); }

  ImageGeometry geometry_;
  double stiffness_;
  Volume signed_;
  Matrix3 toIndex_;
  double step_;
};

// The voxels in two or more masks (one grid), and which masks hold any.
struct Sharing {
  long long voxels = 0;
  std::vector<bool> masks;
};
Sharing sharing(const std::vector<Mask>& masks) {
  Sharing shared;
  shared.masks.assign(masks.size(), false);
  for (std::size_t v = 0; v < masks.front().voxels.size(); ++v) {
    int holders = 0;
    for (const Mask& m : masks) holders += m.voxels[v] != 0;
    if (holders < 2) continue;
    ++shared.voxels;
    for (std::size_t s = 0; s < masks.size(); ++s) shared.masks[s] = shared.masks[s] || masks[s].voxels[v];
  }
  return shared;
}

// The box of every structure's voxels, grown by kTerritoryMargin.
std::pair<std::array<int, 3>, std::array<int, 3>> structuresBox(const std::vector<Mask>& masks) {
  std::vector<std::uint8_t> any(masks.front().voxels.size(), 0);
  for (const Mask& m : masks)
    for (std::size_t v = 0; v < any.size(); ++v) any[v] |= m.voxels[v];
  return occupiedRegion(masks.front().geometry, any, kTerritoryMargin);
}

// The distance (mm) from voxel `v`'s centre to the nearest of `points`;
// infinity for none.
double nearestPoint(const ImageGeometry& grid, std::size_t v, const MatrixX3& points) {
  const std::array<int, 3> voxel = grid.voxelAt(static_cast<long long>(v));
  const Vector3 centre = grid.toPhysical(Vector3(voxel[0], voxel[1], voxel[2]));
  double nearest = std::numeric_limits<double>::infinity();
  for (Eigen::Index p = 0; p < points.rows(); ++p)
    nearest = std::min(nearest, (points.row(p).transpose() - centre).norm());
  return nearest;
}

// Runs segmentImage, naming the structure in its errors.
SegmentOutcome segmentOne(const Volume& image, const StructureInputs& structure, const SegmentParameters& parameters,
                          const ProgressCallback& progress, const Mask* wall = nullptr) {
  try {
    if (!wall) return segmentImage(image, structure.inputs, parameters, progress);
    WallForce force(*wall, parameters.barrierStiffness);
    FieldForceModel barrier(force);
    return segmentImage(image, structure.inputs, parameters, progress, {&barrier});
  } catch (const Error& error) {
    throw Error("structure " + structure.name, error.what());
  }
}

}  // namespace

Volume jointLabels(const std::vector<Mask>& masks, const std::vector<MatrixX3>& evidence) {
  if (masks.empty()) throw Error("no structures to join");
  if (evidence.size() != masks.size()) throw Error("internal: joining structures needs one point set per mask");
  const ImageGeometry& grid = masks.front().geometry;
  for (const Mask& m : masks)
    if (!m.geometry.sameGridAs(grid) || m.voxels.size() != masks.front().voxels.size())
      throw Error("the structures' labelmaps are not on one grid");
  Volume labels;
  labels.geometry = grid;
  labels.voxels.assign(masks.front().voxels.size(), 0.0f);
  for (std::size_t v = 0; v < labels.voxels.size(); ++v) {
    int label = 0;
    double nearest = std::numeric_limits<double>::infinity();
    for (std::size_t s = 0; s < masks.size(); ++s) {
      if (!masks[s].voxels[v]) continue;
      if (label != 0) {
        // A shared voxel (a few hundred in a run): its distance to each
        // claimant's points, the first claimant's only now.
        if (!std::isfinite(nearest)) nearest = nearestPoint(grid, v, evidence[label - 1]);
        const double d = nearestPoint(grid, v, evidence[s]);
        if (d >= nearest) continue;
        nearest = d;
      }
      label = static_cast<int>(s) + 1;
    }
    labels.voxels[v] = static_cast<float>(label);
  }
  return labels;
}

void checkStructures(const std::vector<StructureInputs>& structures, const SegmentParameters& parameters) {
  if (structures.size() < 2) throw Error("segmenting structures together needs two or more");
  std::set<std::string> names;
  for (const StructureInputs& s : structures) {
    if (!usableStructureName(s.name))
      throw Error("structure name '" + s.name +
                  "': use letters, digits, '_', '-' and '.' only (it names the structure's output folder)");
    if (!names.insert(s.name).second)
      throw Error("two structures are named '" + s.name +
                  "' (a list's name makes its folder's, each character other than a letter, a digit, '_', '-' "
                  "and '.' made '_'): give each structure a --name");
    try {
      checkSegmentInputs(s.inputs, parameters);
    } catch (const UsageError& error) {
      throw UsageError("structure " + s.name, error.what());
    } catch (const Error& error) {
      throw Error("structure " + s.name, error.what());
    }
  }
}

StructuresOutcome segmentStructures(const Volume& image, const std::vector<StructureInputs>& structures,
                                    const SegmentParameters& parameters, const ProgressCallback& progress) {
  checkStructures(structures, parameters);
  for (const StructureInputs& s : structures) {
    try {
      requireInsideClickInImage(image, s.inputs);
    } catch (const Error& error) {
      throw Error("structure " + s.name, error.what());
    }
  }
  const auto started = std::chrono::steady_clock::now();
  StructuresOutcome out;
  const std::size_t n = structures.size();
  // Structures started from one atlas share the image's registration to it:
  // the first one's is made once and given to the others.
  // A structure segmented again keeps its own registration and the label
  // its first pass carried to the image.
  std::vector<StructureInputs> inputs = structures;
  std::shared_ptr<const AtlasAffine> registration;
  const Atlas* registered = nullptr;
  for (StructureInputs& s : inputs) {
    if (!s.inputs.atlasAffine && registration && s.inputs.atlas.get() == registered)
      s.inputs.atlasAffine = registration;
    if (s.inputs.start.kind == SegmentStart::Kind::Atlas && !s.inputs.atlasAffine) ++out.atlasRegistrations;
    out.structures.push_back(segmentOne(image, s, parameters, progress));
    if (!s.inputs.atlasAffine) s.inputs.atlasAffine = out.structures.back().atlasAffine;
    if (!registration && s.inputs.atlasAffine) {
      registration = s.inputs.atlasAffine;
      registered = s.inputs.atlas.get();
    }
  }
  const auto masksOf = [&out] {
    std::vector<Mask> masks;
    for (const SegmentOutcome& o : out.structures) masks.push_back(o.labelmap);
    return masks;
  };
  std::vector<Mask> masks = masksOf();
  std::vector<MatrixX3> evidence;
  for (const SegmentOutcome& o : out.structures) evidence.push_back(landmarkPositions(o.springs));
  for (const SegmentOutcome& o : out.structures) out.aloneMetrics.push_back(o.metrics);
  const Sharing alone = sharing(masks);
  out.sharedAlone = alone.voxels;
  out.segmentedAgain.assign(n, false);

  if (out.sharedAlone > 0 && parameters.barrierStiffness > 0) {
    out.segmentedAgain = alone.masks;
    // The territories, on the structures' box.
    const auto [first, size] = structuresBox(masks);
    const Volume territories = cropVolume(jointLabels(masks, evidence), first, size);
    for (std::size_t s = 0; s < n; ++s) {
      if (!out.segmentedAgain[s]) continue;
      std::vector<int> others;
      for (std::size_t t = 0; t < n; ++t)
        if (t != s) others.push_back(static_cast<int>(t + 1));
      const Mask wall = selectLabels(territories, others);
      if (out.structures[s].carried) {
        inputs[s].inputs.atlasCarried = std::make_shared<const CarriedLabel>(std::move(*out.structures[s].carried));
      }
      inputs[s].inputs.resume = std::make_shared<const SegmentResult>(std::move(out.structures[s].result));
      out.structures[s] = segmentOne(image, inputs[s], parameters, progress, &wall);
    }
    masks = masksOf();
  }
  out.sharedTogether = sharing(masks).voxels;
  out.labels = jointLabels(masks, evidence);
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();

  std::vector<Report> listed;
  for (std::size_t s = 0; s < n; ++s) {
    const SegmentInputs& in = structures[s].inputs;
    Report r;
    r.set("index", static_cast<int>(s + 1));
    r.set("name", structures[s].name);
    r.set("landmarks", in.landmarkSource);
    r.set("init", in.start.text);
    if (in.inside) r.set("inside_lps_mm", *in.inside);
    r.set("segmented_again", static_cast<bool>(out.segmentedAgain[s]));
    r.set("volume_mm3",
          static_cast<double>(out.structures[s].labelmap.count()) * out.structures[s].labelmap.geometry.spacing.prod());
    const Mask share = selectLabels(out.labels, {static_cast<int>(s + 1)});
    r.set("joint_volume_mm3", static_cast<double>(share.count()) * share.geometry.spacing.prod());
    if (in.reference) {
      out.jointMetrics.push_back(compareMasks(share, in.reference()));
      r.set("reference", in.referencePath);
      r.set("reference_labels", in.referenceLabels);
      r.set("alone", metricsReport(out.aloneMetrics[s]));
      r.set("own", metricsReport(out.structures[s].metrics));
      r.set("joint", metricsReport(out.jointMetrics.back()));
    } else {
      out.jointMetrics.push_back(OverlapMetrics());
    }
    r.set("warnings", out.structures[s].warnings);
    r.set("trusted", out.structures[s].trustFlags.empty());
    listed.push_back(r);
  }
  Report& report = out.report;
  report.set("image", structures.front().inputs.image);
  report.set("structures", listed);
  report.set("shared_voxels_alone", static_cast<long>(out.sharedAlone));
  report.set("shared_voxels_together", static_cast<long>(out.sharedTogether));
  report.set("barrier_stiffness", parameters.barrierStiffness);
  if (out.atlasRegistrations > 0) report.set("atlas_registrations", out.atlasRegistrations);
  report.set("seconds", out.seconds);
  return out;
}

}  // namespace dynsub
