#include "dynsub/Atlas.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <limits>
#include <optional>
#include <set>
#include <sstream>

#include "BridgeGeometry.h"
#include "ItkRegistration.h"
#include "dynsub/Error.h"
#include "dynsub/TextFields.h"
#include "dynsub/ImageIO.h"
#include "dynsub/RegionGrowing.h"

namespace dynsub {

namespace {

using Clock = std::chrono::steady_clock;

constexpr double kFieldVoxels = 40000;

// A piece of a structure's labels apart from its largest, at least this share
// of its voxels, is a structure of its own. AAL's labels each lie in one
// piece but for islands of at most 0.2 % of their voxels; the two caudates
// given together are two pieces of about half each.
constexpr double kSeparatePiece = 0.05;

std::string labelList(const std::vector<int>& labels) {
  std::vector<std::string> values;
  for (int label : labels) values.push_back(std::to_string(label));
  return joined(values, ",");
}

double secondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

bool endsWith(const std::string& text, const std::string& end) {
  return text.size() >= end.size() && text.compare(text.size() - end.size(), end.size(), end) == 0;
}

// A value a label map can hold: a whole number within a signed 16-bit
// map's range (false for NaN and infinities).
bool isLabelValue(double value) { return std::abs(value) <= 32767 && value == std::floor(value); }

itkbridge::AffineArray toArray(const AffineMap& map) {
  itkbridge::AffineArray a{};
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) a[4 * r + c] = map.linear(r, c);
    a[4 * r + 3] = map.translation[r];
  }
  return a;
}

// `in` moved by whole voxels so that its voxel nearest the click (`point`,
// in the voxel `click`) among those 2 mm deep (or half its greatest depth,
// for a thin one) lands on the click's voxel; `shift` receives the move (mm).
std::vector<std::uint8_t> movedToClick(const std::vector<std::uint8_t>& in, const ImageGeometry& grid,
                                       const Vector3& point, const std::array<int, 3>& click, Vector3& shift) {
  const std::vector<float> depth = depthInside(in, grid);
  const float wanted = std::min(2.0f, 0.5f * *std::max_element(depth.begin(), depth.end()));
  std::array<int, 3> from{};
  double nearest = std::numeric_limits<double>::infinity();
  long long o = 0;
  for (int k = 0; k < grid.size[2]; ++k)
    for (int j = 0; j < grid.size[1]; ++j)
      for (int i = 0; i < grid.size[0]; ++i, ++o) {
        if (!in[o] || depth[o] < wanted) continue;
        const double d = (grid.toPhysical(Vector3(i, j, k)) - point).norm();
        if (d < nearest) {
          nearest = d;
          from = {i, j, k};
        }
      }
  const std::array<int, 3> by = {click[0] - from[0], click[1] - from[1], click[2] - from[2]};
  std::vector<std::uint8_t> moved(in.size(), 0);
  o = 0;
  for (int k = 0; k < grid.size[2]; ++k)
    for (int j = 0; j < grid.size[1]; ++j)
      for (int i = 0; i < grid.size[0]; ++i, ++o)
        if (in[o] && grid.contains(i + by[0], j + by[1], k + by[2]))
          moved[grid.offset(i + by[0], j + by[1], k + by[2])] = 1;
  shift = grid.direction * grid.spacing.cwiseProduct(Vector3(by[0], by[1], by[2]));
  return moved;
}

AffineMap fromArray(const itkbridge::AffineArray& a) {
  AffineMap map;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) map.linear(r, c) = a[4 * r + c];
    map.translation[r] = a[4 * r + 3];
  }
  return map;
}

// Where a label map's table of names may be: labels.nii.gz -> labels.nii.txt,
// then labels.txt, then labels.tsv.
std::vector<std::string> nameTables(const std::string& labelsPath) {
  std::string base = labelsPath;
  if (endsWith(base, ".gz")) base.resize(base.size() - 3);
  std::vector<std::string> candidates = {base + ".txt"};
  std::string stem = base;
  if (const auto dot = base.rfind('.'); dot != std::string::npos && dot > base.find_last_of('/') + 1)
    stem = base.substr(0, dot);
  if (stem != base) candidates.push_back(stem + ".txt");
  candidates.push_back(stem + ".tsv");
  return candidates;
}

// A BIDS table (dseg.tsv): tab-separated columns named on the first line,
// `index` and `name` among them. Nothing when they are not there: such a
// .tsv beside a label map is some other table.
std::optional<LabelNames> readTsvNames(std::istream& in, const std::string& path) {
  std::string line;
  if (!std::getline(in, line)) return std::nullopt;
  std::vector<std::string> header = splitCsvFields(withoutByteOrderMark(line), '\t');
  for (std::string& cell : header) cell = lowerCase(cell);
  const auto index = std::find(header.begin(), header.end(), "index");
  const auto name = std::find(header.begin(), header.end(), "name");
  if (index == header.end() || name == header.end()) return std::nullopt;
  const std::size_t indexColumn = static_cast<std::size_t>(index - header.begin()),
                    nameColumn = static_cast<std::size_t>(name - header.begin());
  LabelNames names;
  for (int number = 2; std::getline(in, line); ++number) {
    if (holdsNothing(line, "\t")) continue;
    const std::vector<std::string> row = splitCsvFields(line, '\t');
    double value = 0;
    if (row.size() <= std::max(indexColumn, nameColumn) || !parseNumber(row[indexColumn], value) ||
        !isLabelValue(value) || row[nameColumn].empty())
      throw Error(path, "line " + std::to_string(number) +
                            ": expected a label value (a whole number from -32767 to 32767) under 'index' and its "
                            "name under 'name'");
    names.emplace_back(static_cast<int>(value), row[nameColumn]);
  }
  return names;
}

}  // namespace

LabelNames readLabelNames(const std::string& labelsPath) {
  for (const std::string& path : nameTables(labelsPath)) {
    std::ifstream in(path);
    if (!in) continue;
    if (endsWith(path, ".tsv")) {
      if (std::optional<LabelNames> names = readTsvNames(in, path)) return *names;
      continue;
    }
    // Each line's value, its words, and where its name's words begin; the
    // name's end is decided for the whole table below.
    struct Line {
      int value;
      std::vector<std::string> words;
      std::size_t first;
    };
    std::vector<Line> lines;
    const auto isNumber = [](const std::string& word) {
      double number = 0;
      return parseNumber(word, number) && std::isfinite(number);
    };
    std::string line;
    int number = 0;
    while (std::getline(in, line)) {
      ++number;
      const std::size_t start = line.find_first_not_of(" \t\r");
      if (start == std::string::npos || line[start] == '#') continue;
      // "VALUE NAME" and whatever numbers tables add before or after the
      // name (mricron's a code after it, ITK-SNAP's colours before it, in
      // quotes, FreeSurfer's colours after it); a name may hold spaces.
      std::istringstream fields(line);
      std::vector<std::string> words;
      for (std::string word; fields >> word;) words.push_back(word);
      double value = 0;
      if (words.empty() || !parseNumber(words.front(), value) || !isLabelValue(value))
        throw Error(path, "line " + std::to_string(number) +
                              ": expected a label value (a whole number from -32767 to 32767) and its name");
      std::size_t first = 1;
      while (first < words.size() && isNumber(words[first])) ++first;
      if (first == words.size())
        throw Error(path, "line " + std::to_string(number) + ": expected a label value and its name");
      lines.push_back({static_cast<int>(value), std::move(words), first});
    }
    // A name's trailing numbers are the table's own (a code, colours) unless
    // leaving them out would give two labels one name ("Brodmann area 17").
    const auto namesOf = [&](bool trailingNumbers) {
      LabelNames names;
      for (const Line& l : lines) {
        std::size_t last = l.words.size();
        while (!trailingNumbers && last > l.first + 1 && isNumber(l.words[last - 1])) --last;
        std::string name;
        for (std::size_t w = l.first; w < last; ++w) name += (name.empty() ? "" : " ") + l.words[w];
        if (name.size() >= 2 && name.front() == '"' && name.back() == '"')
          name = trimmed(name.substr(1, name.size() - 2));
        names.emplace_back(l.value, name);
      }
      return names;
    };
    LabelNames names = namesOf(false);
    std::set<std::string> seen;
    for (const auto& [value, name] : names)
      if (!seen.insert(name).second) return namesOf(true);
    return names;
  }
  return {};
}

AffineMap AffineMap::inverse() const {
  AffineMap inverse;
  inverse.linear = linear.inverse();
  inverse.translation = -inverse.linear * translation;
  return inverse;
}

Atlas readAtlas(const std::string& imagePath, const std::string& labelsPath) {
  Atlas atlas;
  atlas.imagePath = imagePath;
  atlas.labelsPath = labelsPath;
  atlas.image = readVolume(imagePath);
  atlas.labels = readLabelMap(labelsPath);
  if (const std::string difference = atlas.labels.geometry.differenceFrom(atlas.image.geometry, "template");
      !difference.empty())
    throw Error(labelsPath, "the atlas's label map is not on its template's grid (" + imagePath + "): " + difference);
  atlas.names = readLabelNames(labelsPath);
  return atlas;
}

namespace {

// One item of a label spec (labelSpecValues).
int labelValue(const std::string& item, const std::string& spec, const std::string& labelsPath,
               const std::function<const LabelNames&()>& table, const std::string& option) {
  double number = 0;
  if (parseNumber(item, number) && std::isfinite(number)) {
    if (!isLabelValue(number)) throw UsageError(option + " " + spec + ": " + item + " is not a label value");
    // 0 is every label map's background, no structure.
    if (number == 0) throw UsageError(option + " " + spec + ": 0 is the label map's background, not a structure");
    return static_cast<int>(number);
  }
  const LabelNames& names = table();
  // The name as written, else the one name that matches it whatever the
  // case: two labels can differ by case alone.
  auto named = std::find_if(names.begin(), names.end(), [&](const auto& entry) { return entry.second == item; });
  if (named != names.end() && std::count_if(names.begin(), names.end(), [&](const auto& entry) {
                                return entry.second == item && entry.first != named->first;
                              }) > 0)
    throw UsageError(option + " " + spec + ": '" + item + "' names more than one label of " + labelsPath +
                     "; give the label value instead");
  if (named == names.end()) {
    std::vector<std::string> matches;
    for (const auto& entry : names)
      if (lowerCase(entry.second) == lowerCase(item)) {
        if (matches.empty()) named = std::find(names.begin(), names.end(), entry);
        matches.push_back("'" + entry.second + "' (" + std::to_string(entry.first) + ")");
      }
    if (matches.size() > 1)
      throw UsageError(option + " " + spec + ": '" + item + "' matches " + std::to_string(matches.size()) +
                       " labels of " + labelsPath + " that differ by case alone: " + joined(matches, ", ") +
                       "; write it as one of them is written");
  }
  if (named != names.end()) {
    if (named->first == 0)
      throw UsageError(option + " " + spec + ": '" + named->second +
                       "' is label 0, the label map's background, not a structure");
    return named->first;
  }
  if (names.empty())
    throw Error(labelsPath, "no table of label names beside it (" + joined(nameTables(labelsPath), " or ") +
                                "): give " + option + " as numbers, not '" + item + "'");
  // The names that hold it ("Caudate": both sides), else the nearest.
  std::vector<std::string> holding;
  for (const auto& entry : names)
    if (lowerCase(entry.second).find(lowerCase(item)) != std::string::npos) holding.push_back("'" + entry.second + "'");
  if (holding.empty() || holding.size() > 4) {
    const auto nearest = std::min_element(names.begin(), names.end(), [&](const auto& a, const auto& b) {
      return editDistance(a.second, item) < editDistance(b.second, item);
    });
    holding.assign(1, "'" + nearest->second + "'");
  }
  throw Error(labelsPath, "no label named '" + item + "' (did you mean " + joined(holding, " or ") + "?)");
}

}  // namespace

std::vector<int> labelSpecValues(const std::string& spec, const std::string& labelsPath,
                                 const std::function<const LabelNames&()>& names, const std::string& option) {
  if (spec.empty()) throw UsageError(option + ": no label given");
  std::vector<int> values;
  for (const std::string& written : splitItems(spec, ',')) {  // "71," and "71,,72" have an empty item
    const std::string item = trimmed(written);
    if (item.empty()) throw UsageError(option + " " + spec + ": an empty label");
    values.push_back(labelValue(item, spec, labelsPath, names, option));
  }
  return values;
}

std::vector<int> atlasLabelValues(const Atlas& atlas, const std::string& spec, const std::string& option) {
  const std::vector<int> values = labelSpecValues(
      spec, atlas.labelsPath, [&atlas]() -> const LabelNames& { return atlas.names; }, option);
  for (int value : values)
    if (selectLabels(atlas.labels, {value}).count() == 0)
      throw Error(atlas.labelsPath, "no voxel has the label " + std::to_string(value));
  // One surface is one piece: labels that lie apart (the two caudates) would
  // be joined by a bridge through whatever lies between them. A label of its
  // own is the atlas's structure as the atlas draws it (a click inside picks
  // its piece).
  if (values.size() < 2) return values;
  const Mask selected = selectLabels(atlas.labels, values);
  const std::vector<long long> sizes = pieceSizes(selected.voxels, selected.geometry);
  long long total = 0;
  for (long long size : sizes) total += size;
  if (sizes.size() > 1 && static_cast<double>(sizes[1]) >= kSeparatePiece * static_cast<double>(total)) {
    std::vector<std::string> voxels;
    for (std::size_t p = 0; p < sizes.size() && p < 4; ++p) voxels.push_back(std::to_string(sizes[p]));
    throw UsageError(option + " " + spec + ": the labels lie in " + std::to_string(sizes.size()) +
                     " separate pieces in " + atlas.labelsPath + " (" + joined(voxels, ", ") +
                     (sizes.size() > 4 ? ", ..." : "") +
                     " voxels), and one surface cannot hold separate pieces: give each structure an --atlas-label "
                     "of its own (segmented together, they do not overlap)");
  }
  return values;
}

std::string atlasStructureName(const Atlas& atlas, const std::vector<int>& values, const std::string& spec) {
  if (values.empty()) return spec;
  const auto named = std::find_if(atlas.names.begin(), atlas.names.end(),
                                  [&values](const auto& entry) { return entry.first == values.front(); });
  return values.size() == 1 && named != atlas.names.end() ? named->second : spec;
}

void checkAtlasRegistrationOptions(const AtlasRegistrationOptions& o) {
  auto positiveLevels = [](const std::vector<double>& levels, const char* name) {
    if (levels.empty()) throw Error(std::string(name) + " must name at least one level");
    for (double level : levels)
      if (!std::isfinite(level) || level <= 0) throw Error(std::string(name) + " must be positive sizes in mm");
  };
  positiveLevels(o.affineLevelsMm, "the affine registration's levels");

  auto positive = [](double value, const char* name) {
    if (!std::isfinite(value) || value <= 0) throw Error(std::string(name) + " must be a positive number");
  };
  positive(o.deformableLevelMm, "the deformable registration's voxel size");
  positive(o.updateSigmaMm, "the deformable registration's update smoothing");
  requireFiniteNonNegative(o.totalSigmaMm, "the deformable registration's field smoothing");
  requireFiniteNonNegative(o.marginMm, "the deformable registration's margin");
  if (o.affineIterations < 1 || o.deformableIterations < 1)
    throw Error("the registrations need at least one iteration per level");
  if (!(o.samplingFraction > 0 && o.samplingFraction <= 1))
    throw Error("the registration's sampling fraction must lie in (0, 1]");
}

AtlasAffine registerAtlasAffine(const Volume& subject, const Atlas& atlas, const AtlasRegistrationOptions& options) {
  checkAtlasRegistrationOptions(options);
  const auto started = Clock::now();
  itkbridge::AffineSettings settings;
  settings.levelsMm = options.affineLevelsMm;
  settings.iterations = options.affineIterations;
  settings.samplingFraction = options.samplingFraction;
  const itkbridge::AffineOutcome outcome = itkbridge::registerAffine(
      toBridge(subject.geometry), subject.voxels, toBridge(atlas.image.geometry), atlas.image.voxels, settings);
  AtlasAffine affine;
  affine.map = fromArray(outcome.transform);
  affine.metric = outcome.metric;
  affine.iterations = outcome.iterations;
  affine.seconds = secondsSince(started);
  // A head maps to a head: a scale beyond 1:3 either way is a failed registration.
  const double determinant = affine.map.linear.determinant();
  if (!affine.map.linear.allFinite() || !affine.map.translation.allFinite() || !(determinant > 1.0 / 27) ||
      !(determinant < 27))
    throw Error(atlas.imagePath, "the registration of the atlas to the image failed (a degenerate transform)");
  return affine;
}

CarriedLabel carryLabel(const Volume& subject, const Atlas& atlas, const std::vector<int>& labels,
                        const AtlasAffine& affine, const std::optional<Vector3>& inside,
                        const AtlasRegistrationOptions& options) {
  checkAtlasRegistrationOptions(options);
  const auto started = Clock::now();
  if (inside && (!inside->allFinite() || !subject.geometry.covers(*inside))) {
    std::ostringstream message;
    message << "the click inside the structure (" << inside->x() << ", " << inside->y() << ", " << inside->z()
            << ") mm LPS lies outside the image";
    throw LandmarkError(message.str());
  }
  const Mask structure = selectLabels(atlas.labels, labels);
  const ImageGeometry& atlasGrid = atlas.labels.geometry;
  const auto [atlasFirst, atlasSize] = occupiedRegion(atlasGrid, structure.voxels, 0);
  if (atlasSize[0] == 0) throw Error(atlas.labelsPath, "the labels hold no voxel");

  // The structure's box in the template, through the inverse map, grown by
  // the margin: where the subject is registered and labelled.
  const AffineMap toSubject = affine.map.inverse();
  MatrixX3 corners(8, 3);
  for (int c = 0; c < 8; ++c) {
    Vector3 index;
    for (int a = 0; a < 3; ++a) index[a] = atlasFirst[a] + (((c >> a) & 1) ? atlasSize[a] - 1 : 0);
    corners.row(c) = toSubject(atlasGrid.toPhysical(index)).transpose();
  }
  if (inside) {
    corners.conservativeResize(9, 3);
    corners.row(8) = inside->transpose();
  }
  const auto [first, size] = boundingRegion(subject.geometry, corners, options.marginMm);
  if (std::min({size[0], size[1], size[2]}) < 4)
    throw Error(atlas.labelsPath, "the structure's labels (" + labelList(labels) +
                                      ") fall outside the image after its registration to the template " +
                                      atlas.imagePath + ": does the image hold the structure?");
  const Volume region = cropVolume(subject, first, size);

  itkbridge::DeformableSettings settings;
  // A large structure's field is coarser: at most kFieldVoxels voxels, so
  // that the cerebellum's registration takes about as long as a caudate's.
  const double regionVolume = region.geometry.spacing.prod() * static_cast<double>(region.geometry.voxelCount());
  settings.levelMm = std::max(options.deformableLevelMm, std::cbrt(regionVolume / kFieldVoxels));
  settings.iterations = options.deformableIterations;
  settings.updateSigmaMm = options.updateSigmaMm;
  settings.totalSigmaMm = options.totalSigmaMm;
  const itkbridge::DeformableOutcome warp =
      itkbridge::registerDeformable(toBridge(region.geometry), region.voxels, toBridge(atlas.image.geometry),
                                    atlas.image.voxels, toArray(affine.map), settings);

  // Each voxel takes the structure's share at its template point
  // (trilinear in the template's mask), in when at least half.
  CarriedLabel carried;
  carried.first = first;
  carried.metric = warp.metric;
  carried.iterations = warp.iterations;
  const ImageGeometry& grid = region.geometry;
  std::vector<std::uint8_t> in(static_cast<std::size_t>(grid.voxelCount()), 0);
  const Matrix3 toAtlasIndex = atlasGrid.indexFromPhysical();
  long long o = 0;
  const ImageGeometry field = fromBridge(warp.field);
  const Matrix3 toFieldIndex = field.indexFromPhysical();
  for (int k = 0; k < grid.size[2]; ++k)
    for (int j = 0; j < grid.size[1]; ++j)
      for (int i = 0; i < grid.size[0]; ++i, ++o) {
        const Vector3 x = grid.toPhysical(Vector3(i, j, k));
        const Trilinear at = trilinearAt(field, toFieldIndex * (x - field.origin));
        Vector3 d = Vector3::Zero();
        for (int c = 0; c < 8; ++c)
          for (int a = 0; a < 3; ++a) d[a] += at.weight[c] * warp.displacement[3 * at.offset[c] + a];
        const Vector3 y = affine.map(x + d);
        carried.largestWarpMm = std::max(carried.largestWarpMm, d.norm());
        const Vector3 index = toAtlasIndex * (y - atlasGrid.origin);
        bool within = true;
        for (int a = 0; a < 3; ++a) within = within && index[a] >= -0.5 && index[a] <= atlasGrid.size[a] - 0.5;
        if (!within) continue;
        const Trilinear corners = trilinearAt(atlasGrid, index);
        double share = 0;
        for (int c = 0; c < 8; ++c) share += corners.weight[c] * structure.voxels[corners.offset[c]];
        in[o] = share >= 0.5;
      }
  if (std::none_of(in.begin(), in.end(), [](std::uint8_t v) { return v != 0; }))
    throw Error(atlas.labelsPath, "the structure's labels (" + labelList(labels) +
                                      ") fall outside the image after its registration to the template " +
                                      atlas.imagePath + ": does the image hold the structure?");

  if (inside) {
    // The click's voxel on the region's grid.
    const Vector3 index = grid.toIndex(*inside);
    std::array<int, 3> click{};
    for (int a = 0; a < 3; ++a) click[a] = std::clamp(static_cast<int>(std::lround(index[a])), 0, grid.size[a] - 1);
    const long long at = grid.offset(click[0], click[1], click[2]);
    if (!in[at]) in = movedToClick(in, grid, *inside, click, carried.shift);
    in = connectedTo(in, grid, {at});
  }
  carried.mask = Mask{grid, fillHoles(in, grid)};
  carried.seconds = secondsSince(started);
  return carried;
}

std::vector<Landmark> carriedBoundary(const CarriedLabel& label, int count) {
  bool touchesSide = false;
  const std::vector<Vector3> faces = boundaryFaces(label.mask.voxels, label.mask.geometry, &touchesSide);
  if (faces.size() < 4) throw Error("the atlas's structure carried to the image is too small to start a surface from");
  Vector3 centre = Vector3::Zero();
  for (const Vector3& face : faces) centre += face;
  centre /= static_cast<double>(faces.size());
  const std::vector<Vector3> spread = farthestPointSample(faces, centre, static_cast<std::size_t>(count));
  std::vector<Landmark> points;
  for (std::size_t p = 0; p < spread.size(); ++p) points.push_back({"atlas " + std::to_string(p + 1), spread[p]});
  return points;
}

double carriedVolume(const CarriedLabel& label) {
  return static_cast<double>(label.mask.count()) * label.mask.geometry.spacing.prod();
}

}  // namespace dynsub
