#include "dynsub/Evaluation.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <mutex>
#include <set>
#include <thread>

#include <nlohmann/json.hpp>

#include "dynsub/Error.h"
#include "dynsub/FileNames.h"
#include "dynsub/ImageIO.h"
#include "dynsub/Metrics.h"
#include "dynsub/SegmentImage.h"
#include "dynsub/SegmentStructures.h"
#include "dynsub/SubjectGenerator.h"
#include "dynsub/TextFields.h"

namespace dynsub {

namespace {

int axisOf(const std::string& orientation, const std::string& where) {
  if (orientation == "sagittal") return 0;
  if (orientation == "coronal") return 1;
  if (orientation == "axial") return 2;
  throw Error(where + ": orientation must be sagittal, coronal or axial, got '" + orientation + "'");
}

// The plan's paths are relative to the plan's own directory.
std::string resolve(const std::string& path, const std::filesystem::path& base) {
  const std::filesystem::path p(path);
  return p.is_absolute() ? path : (base / p).lexically_normal().string();
}

// A whole number in the plan, in low..high: what its field can hold (the
// settings' own checks hold it to their ranges after). nlohmann's get<int>()
// would read 1.5 as 1 and get<unsigned>() -1 as 4294967295, silently; 2.0 is
// taken as 2.
long long wholeNumber(const nlohmann::json& value, const std::string& what, long long low, long long high) {
  const double number = value.is_number() ? value.get<double>() : std::numeric_limits<double>::quiet_NaN();
  if (!(number == std::floor(number))) throw Error(what + " must be a whole number, got " + value.dump());
  if (!(number >= low && number <= high))
    throw Error(what + " must be in " + std::to_string(low) + ".." + std::to_string(high) + ", got " + value.dump());
  return static_cast<long long>(number);
}
// The largest count, level or label a plan may give: beyond any it means, and an int.
constexpr long long kLargestSetting = 1 << 30;
// `object`'s `key` as a whole number in 0..kLargestSetting, or `fallback` when it has none.
int optionalWholeNumber(const nlohmann::json& object, const char* key, int fallback, const std::string& where) {
  if (!object.contains(key)) return fallback;
  return static_cast<int>(wholeNumber(object.at(key), where + key, 0, kLargestSetting));
}

// The plan's values, each of the JSON type its field needs: nlohmann's own
// conversions would say "[json.exception.type_error.302] type must be
// string, but is number" without saying where.
const nlohmann::json& required(const nlohmann::json& object, const char* key, const std::string& where) {
  if (!object.contains(key)) throw Error(where + " has no '" + key + "'");
  return object.at(key);
}
std::string textOf(const nlohmann::json& value, const std::string& what) {
  if (!value.is_string()) throw Error(what + " must be a string, got " + value.dump());
  return value.get<std::string>();
}
double realOf(const nlohmann::json& value, const std::string& what) {
  if (!value.is_number()) throw Error(what + " must be a number, got " + value.dump());
  return value.get<double>();
}
bool flagOf(const nlohmann::json& value, const std::string& what) {
  if (!value.is_boolean()) throw Error(what + " must be true or false, got " + value.dump());
  return value.get<bool>();
}
const nlohmann::json& listOf(const nlohmann::json& value, const std::string& what) {
  if (!value.is_array()) throw Error(what + " must be a list, got " + value.dump());
  return value;
}
// `object`'s optional list `key`, empty where it has none.
nlohmann::json optionalList(const nlohmann::json& object, const char* key, const std::string& where) {
  return object.contains(key) ? listOf(object.at(key), where + key) : nlohmann::json::array();
}

// A key given twice in one object: nlohmann keeps the last, silently, where
// the first may be the one meant.
nlohmann::json parseWithoutRepeatedKeys(std::istream& in) {
  std::vector<std::set<std::string>> keys;  // one set per object open
  const nlohmann::json::parser_callback_t check = [&keys](int, nlohmann::json::parse_event_t event,
                                                          nlohmann::json& parsed) {
    using Event = nlohmann::json::parse_event_t;
    if (event == Event::object_start) keys.emplace_back();
    if (event == Event::object_end) keys.pop_back();
    if (event == Event::key && !keys.back().insert(parsed.get<std::string>()).second)
      throw Error("the key '" + parsed.get<std::string>() + "' is given twice in one object");
    return true;
  };
  // parse reads to the end: anything after the plan's object is an error.
  return nlohmann::json::parse(in, check);
}

// A result keeping less than this fraction of the reference's volume has collapsed.
constexpr double kCollapsedBelowReference = 0.2;

// An atlas protocol's start: the plan's atlas, the structure's labels in it
// and the image's affine registration to it, made once per image.
struct AtlasContext {
  std::shared_ptr<const Atlas> atlas;
  std::vector<int> labels;
  std::shared_ptr<const AtlasAffine> affine;
};

EvaluationRun runOne(const EvaluationPlan& plan, const Volume& image, const Mask& reference,
                     const EvaluationProtocol& protocol, int axis, EvaluationRun run,
                     const std::string& landmarkDirectory, const AtlasContext& atlas) {
  ClickProtocol clicks = protocol.clicks;
  if (!protocol.ownAxis) clicks.axis = axis;
  // The clicks go through a file in the protocol's format, as a user's would.
  std::vector<Landmark> landmarks =
      protocol.noClicks || clicks.seedOnly ? std::vector<Landmark>{} : expertClicks(reference, clicks, run.seed);
  SegmentInputs inputs;
  inputs.landmarkSource = run.protocol;
  if (!landmarks.empty()) {
    const std::string path = (std::filesystem::path(landmarkDirectory) /
                              (run.split + "_" + run.image + (run.subject.empty() ? "" : "_" + run.subject) + "_" + run.structure + "_" + run.protocol + "_" +
                               std::to_string(run.seed) + "." + run.format)).string();
    writeLandmarks(landmarks, path);
    landmarks = readLandmarks(path);
    inputs.landmarkSource = path;
  }
  run.landmarks = static_cast<int>(landmarks.size());
  inputs.landmarks = landmarks;
  if (protocol.atlas) {  // as segment --init atlas [--inside x,y,z]
    inputs.start.kind = SegmentStart::Kind::Atlas;
    inputs.atlas = atlas.atlas;
    inputs.atlasLabels = atlas.labels;
    inputs.atlasAffine = atlas.affine;
    if (clicks.seedOnly) inputs.inside = seedClick(reference, clicks.seedDepth, run.seed);
  } else if (clicks.seedOnly) {  // as segment --init seed: does without landmarks
    inputs.start.kind = SegmentStart::Kind::Seed;
    inputs.start.center = seedClick(reference, clicks.seedDepth, run.seed);
  }
  // Scored on the reference's grid (see the header).
  inputs.labelmapGrid = reference.geometry;
  const SegmentOutcome outcome = segmentImage(image, inputs, plan.parameters);
  const SegmentResult& result = outcome.result;
  run.steps = result.steps;
  for (const std::string& w : outcome.warnings) run.warnings += (run.warnings.empty() ? "" : "; ") + w;
  run.controlVertices = result.mesh.vertexCount();
  run.surfaceOnEdges = result.surfaceOnEdges;
  run.trust = outcome.trust;
  for (const TrustFlag& f : outcome.trustFlags) run.trustFlags += (run.trustFlags.empty() ? "" : " ") + f.name;
  run.seconds = outcome.seconds;
  run.convention = outcome.convention;

  const Mask& mask = outcome.labelmap;
  const double voxel = reference.geometry.spacing.prod();
  long long overlap = 0;
  for (size_t i = 0; i < mask.voxels.size(); ++i) overlap += mask.voxels[i] && reference.voxels[i];
  run.volume = mask.count() * voxel;
  run.referenceVolume = reference.count() * voxel;
  run.leak = run.volume - overlap * voxel;
  run.miss = run.referenceVolume - overlap * voxel;
  run.collapsed = run.volume < kCollapsedBelowReference * run.referenceVolume;
  run.meanSurfaceDistance = run.hd95 = std::numeric_limits<double>::quiet_NaN();  // no surface to measure
  if (mask.count() > 0) {
    const OverlapMetrics m = compareMasks(mask, reference);
    run.dice = m.dice;
    run.jaccard = m.jaccard;
    run.meanSurfaceDistance = m.meanSurfaceDistance;
    run.hd95 = m.hd95;
  }
  return run;
}

// A key the plan's reader does not know is a typo ("slice" for "slices")
// that would otherwise run with a default, unseen.
void requireKnownKeys(const nlohmann::json& object, std::initializer_list<const char*> known,
                      const std::string& where) {
  if (!object.is_object()) throw Error(where + ": expected a JSON object");
  for (const auto& [key, value] : object.items()) {
    if (std::none_of(known.begin(), known.end(), [&key = key](const char* k) { return key == k; })) {
      std::string list;
      for (const char* k : known) list += (list.empty() ? "" : ", ") + std::string(k);
      throw Error(where + ": unknown key '" + key + "' (known: " + list + ")");
    }
  }
}

}  // namespace

EvaluationPlan readEvaluationPlan(const std::string& path) {
  std::ifstream in = openForReading(path);
  nlohmann::json j;
  try {
    j = parseWithoutRepeatedKeys(in);
  } catch (const nlohmann::json::exception& e) {
    throw Error(path, "not valid JSON: " + withoutLibraryTag(e.what()));
  } catch (const Error& e) {
    throw Error(path, e.what());
  }
  const std::filesystem::path base = std::filesystem::absolute(path).parent_path();
  EvaluationPlan plan;
  plan.path = path;
  try {
    requireKnownKeys(j, {"images", "reference", "atlas", "cohorts", "structures", "protocols", "segment", "splits"},
                     "the plan");
    for (const auto& i : optionalList(j, "images", "the plan's ")) requireKnownKeys(i, {"name", "path"}, "an image");
    for (const auto& c : optionalList(j, "cohorts", "the plan's "))
      requireKnownKeys(c, {"name", "image", "labels", "settings", "subjects"}, "a cohort");
    for (const auto& st : optionalList(j, "structures", "the plan's "))
      requireKnownKeys(st, {"name", "labels", "orientation"}, "a structure");
    for (const auto& p : optionalList(j, "protocols", "the plan's "))
      requireKnownKeys(p, {"name", "slices", "points_per_slice", "coverage", "scatter_mm", "mistakes",
                           "mistake_distance_mm", "orientation", "atlas", "clicks", "seed_only", "seed_depth",
                           "format"},
                       "a protocol");
    for (const auto& sp : optionalList(j, "splits", "the plan's "))
      requireKnownKeys(sp, {"name", "seeds", "structures"}, "a split");
    if (j.contains("atlas")) requireKnownKeys(j.at("atlas"), {"image", "labels"}, "the atlas");
    if (j.contains("images")) {
      plan.reference = resolve(textOf(required(j, "reference", "the plan, which has images,"), "the reference"), base);
      for (const auto& i : j.at("images")) {
        const std::string name = textOf(required(i, "name", "an image"), "an image's name");
        const std::string where = "image '" + name + "'";
        plan.images.push_back({name, resolve(textOf(required(i, "path", where), where + ": path"), base)});
      }
    }
    if (j.contains("atlas")) {
      const nlohmann::json& atlas = j.at("atlas");
      plan.atlasImage = resolve(textOf(required(atlas, "image", "the atlas"), "the atlas's image"), base);
      plan.atlasLabels = resolve(textOf(required(atlas, "labels", "the atlas"), "the atlas's labels"), base);
    }
    // Where each subject was drawn. A seed draws the same anatomy whatever
    // the other settings, so from the same image or the same labels (one
    // file, by whatever path) it serves one split only, across cohorts too;
    // the versions of one subject in several cohorts (at 1 mm and in thick
    // slices, say) stay in one split.
    struct Drawn {
      std::string cohort, split, image, labels;
      std::uint64_t seed;
    };
    std::vector<Drawn> drawn;
    const auto sameFile = [](const std::string& a, const std::string& b) {
      std::error_code error;
      const bool same = std::filesystem::equivalent(a, b, error);
      return error ? std::filesystem::weakly_canonical(a, error) == std::filesystem::weakly_canonical(b, error) : same;
    };
    for (const auto& c : optionalList(j, "cohorts", "the plan's ")) {
      const std::string name = textOf(required(c, "name", "a cohort"), "a cohort's name");
      const std::string where = "cohort '" + name + "'";
      EvaluationCohort cohort{name, resolve(textOf(required(c, "image", where), where + ": image"), base),
                              resolve(textOf(required(c, "labels", where), where + ": labels"), base), {}, {}};
      const nlohmann::json settings = c.value("settings", nlohmann::json::object());
      if (!settings.is_object()) throw Error(where + ": settings must be an object, got " + settings.dump());
      for (const auto& [key, value] : settings.items()) {
        std::string text;
        if (value.is_array()) {
          for (const auto& v : value) text += (text.empty() ? "" : ",") + v.dump();
        } else {
          text = value.is_string() ? value.get<std::string>() : value.dump();
        }
        setSubjectSetting(cohort.settings, key, text);
      }
      checkSubjectSettings(cohort.settings);
      const nlohmann::json& subjects = required(c, "subjects", where);
      if (!subjects.is_object())
        throw Error(where + ": subjects must be an object of lists by split, got " + subjects.dump());
      for (const auto& [split, seeds] : subjects.items()) {
        std::vector<std::uint64_t> list;
        for (const auto& seed : listOf(seeds, where + ": split '" + split + "'")) {
          list.push_back(static_cast<std::uint64_t>(wholeNumber(seed, where + ": a subject", 0, kLargestSetting)));
          const std::string subject = "subject " + std::to_string(list.back());
          for (const Drawn& earlier : drawn) {
            if (earlier.seed != list.back()) continue;
            if (earlier.cohort == name)
              throw Error(path, where + ": " + subject + " is listed twice" +
                                    (earlier.split == split ? " in split '" + split + "'"
                                                            : " (in splits '" + earlier.split + "' and '" + split +
                                                                  "': tuning and test subjects must be disjoint)"));
            const bool image = sameFile(earlier.image, cohort.image), labels = sameFile(earlier.labels, cohort.labels);
            if (earlier.split != split && (image || labels))
              throw Error(path, where + ": " + subject + " is in split '" + split + "', and cohort '" + earlier.cohort +
                                    "' draws it from the same " + (image ? "image" : "labels") + " in split '" +
                                    earlier.split + "': a seed draws the same anatomy, so tuning and " +
                                    "test subjects would not be disjoint");
          }
          drawn.push_back({name, split, cohort.image, cohort.labels, list.back()});
        }
        if (list.empty()) throw Error(path, where + ": split '" + split + "' has no subjects");
        cohort.subjects.emplace_back(split, list);
      }
      plan.cohorts.push_back(cohort);
    }
    for (const auto& s : optionalList(j, "structures", "the plan's ")) {
      const std::string name = textOf(required(s, "name", "a structure"), "a structure's name");
      const std::string where = "structure '" + name + "'";
      std::vector<int> labels;
      for (const auto& label : listOf(required(s, "labels", where), where + ": labels"))
        labels.push_back(
            static_cast<int>(wholeNumber(label, where + ": a label (0 is the background)", 1, kLargestSetting)));
      if (labels.empty()) throw Error(path, where + " has no labels");
      plan.structures.push_back(
          {name, labels, axisOf(textOf(required(s, "orientation", where), where + ": orientation"), where)});
    }
    for (const auto& p : optionalList(j, "protocols", "the plan's ")) {
      EvaluationProtocol protocol;
      ClickProtocol& c = protocol.clicks;
      c.name = textOf(required(p, "name", "a protocol"), "a protocol's name");
      const std::string where = "protocol '" + c.name + "': ";
      // `p`'s `key` read by `read`, or `fallback` where it has none.
      const auto optional = [&](const char* key, auto read, auto fallback) {
        return p.contains(key) ? read(p.at(key), where + key) : fallback;
      };
      c.seedOnly = optional("seed_only", flagOf, false);
      c.seedDepth = optional("seed_depth", realOf, c.seedDepth);
      c.slices = optionalWholeNumber(p, "slices", c.slices, where);
      c.pointsPerSlice = optionalWholeNumber(p, "points_per_slice", c.pointsPerSlice, where);
      if (p.contains("coverage")) {
        const nlohmann::json& coverage = listOf(p.at("coverage"), where + "coverage");
        if (coverage.size() != 2) throw Error(path, where + "coverage is [low, high]");
        c.coverageLow = realOf(coverage[0], where + "coverage's low");
        c.coverageHigh = realOf(coverage[1], where + "coverage's high");
      }
      c.scatter = optional("scatter_mm", realOf, c.scatter);
      c.mistakes = optionalWholeNumber(p, "mistakes", c.mistakes, where);
      c.mistakeDistance = optional("mistake_distance_mm", realOf, c.mistakeDistance);
      if (p.contains("orientation")) {
        protocol.ownAxis = true;
        c.axis = axisOf(textOf(p.at("orientation"), where + "orientation"), "protocol '" + c.name + "'");
      }
      protocol.atlas = optional("atlas", flagOf, false);
      protocol.noClicks = !optional("clicks", flagOf, true);
      if (protocol.noClicks && !protocol.atlas)
        throw Error(path, "protocol '" + c.name + "': only an atlas protocol can do without clicks");
      protocol.format = optional("format", textOf, protocol.format);
      if (protocol.format != "mrk.json" && protocol.format != "fcsv" && protocol.format != "csv" &&
          protocol.format != "rotate")
        throw Error(path, "protocol '" + c.name + "': format must be mrk.json, fcsv, csv or rotate");
      checkClickProtocol(c);
      plan.protocols.push_back(protocol);
    }
    if (j.contains("segment")) {
      if (!j.at("segment").is_object())
        throw Error("the plan's segment must be an object of settings, got " + j.at("segment").dump());
      // Settings to compare on the tuning split, by the keys of report.json's
      // "parameters" (SegmentParameters.h); an unknown key is an error, not a
      // silent default.
      for (const auto& [key, value] : j.at("segment").items()) {
        const Parameter* parameter = findSegmentParameter(key);
        if (!parameter) throw Error(path, "unknown segment setting '" + key + "'");
        ParameterValue v;
        if (value.is_boolean()) v = value.get<bool>();
        else if (value.is_string()) v = value.get<std::string>();
        else if (value.is_number()) v = value.get<double>();
        else if (!value.is_null()) throw Error("segment setting " + key + ": not a number, string or boolean");
        try {
          setParameter(plan.parameters, *parameter, v);
        } catch (const Error& e) {
          throw Error("segment setting " + std::string(e.what()));
        }
      }
      checkSegmentParameters(plan.parameters);
    }
    for (const auto& s : optionalList(j, "splits", "the plan's ")) {
      const std::string name = textOf(required(s, "name", "a split"), "a split's name");
      const std::string where = "split '" + name + "'";
      EvaluationSplit split{name, {}, {}};
      for (const auto& structure : optionalList(s, "structures", where + ": "))
        split.structures.push_back(textOf(structure, where + ": a structure"));
      // Left out, the key means every structure; an empty list is a slip.
      if (s.contains("structures") && split.structures.empty())
        throw Error(path, where + " lists no structures (leave \"structures\" out for all of them)");
      for (const auto& seed : listOf(required(s, "seeds", where), where + ": seeds")) {
        split.seeds.push_back(static_cast<unsigned>(
            wholeNumber(seed, "split '" + split.name + "': a seed", 0, std::numeric_limits<unsigned>::max())));
        // A seed twice would run the same clicks twice into the same files.
        if (std::count(split.seeds.begin(), split.seeds.end(), split.seeds.back()) > 1)
          throw Error(path, "split '" + split.name + "' lists seed " + std::to_string(split.seeds.back()) + " twice");
      }
      if (split.seeds.empty()) throw Error(path, "split '" + split.name + "' has no seeds");
      for (const std::string& name : split.structures) {
        bool known = false;
        for (const auto& structure : plan.structures) known = known || structure.name == name;
        if (!known) throw Error(path, "split '" + split.name + "' names unknown structure '" + name + "'");
      }
      plan.splits.push_back(split);
    }
  } catch (const nlohmann::json::exception& e) {
    throw Error(path, "not an evaluation plan: " + withoutLibraryTag(e.what()));
  } catch (const Error& e) {
    const std::string message = e.what();
    throw Error(message.rfind(path, 0) == 0 ? message : path + ": " + message);
  }
  if ((plan.images.empty() && plan.cohorts.empty()) || plan.structures.empty() || plan.protocols.empty() ||
      plan.splits.empty())
    throw Error(path, "an evaluation plan needs images or cohorts, structures, protocols and splits");
  for (const EvaluationCohort& cohort : plan.cohorts)
    for (const auto& [split, seeds] : cohort.subjects) {
      bool known = false;
      for (const EvaluationSplit& s : plan.splits) known = known || s.name == split;
      if (!known) throw Error(path, "cohort '" + cohort.name + "' names unknown split '" + split + "'");
    }
  // On a plan's images every split runs: two splits that share a click seed
  // and a structure would run the same clicks, and a tuning figure would be
  // reported again as a test one.
  if (!plan.images.empty())
    for (std::size_t a = 0; a < plan.splits.size(); ++a)
      for (std::size_t b = a + 1; b < plan.splits.size(); ++b) {
        const EvaluationSplit &first = plan.splits[a], &second = plan.splits[b];
        for (const EvaluationStructure& structure : plan.structures) {
          const auto runs = [&](const EvaluationSplit& split) {
            return split.structures.empty() || std::find(split.structures.begin(), split.structures.end(),
                                                         structure.name) != split.structures.end();
          };
          if (!runs(first) || !runs(second)) continue;
          for (unsigned seed : first.seeds)
            if (std::find(second.seeds.begin(), second.seeds.end(), seed) != second.seeds.end())
              throw Error(path, "splits '" + first.name + "' and '" + second.name + "' share seed " +
                                    std::to_string(seed) + " for structure '" + structure.name +
                                    "': on the plan's images they would run the same clicks (each split's seeds "
                                    "must be its own)");
        }
      }
  // Names make the runs' file names and the summary's groups: each once, and
  // each a plain file name (no '/' or "..": nothing is written outside the
  // directories asked for).
  auto unique = [&](const auto& entries, const auto& nameOf, const char* what) {
    std::set<std::string> seen;
    for (const auto& entry : entries) {
      if (!usableStructureName(nameOf(entry)))
        throw Error(path, "'" + nameOf(entry) + "' is not a usable name for one of the " + what +
                              ": use letters, digits, '_', '-' and '.' (names make file names)");
      if (!seen.insert(nameOf(entry)).second)
        throw Error(path, std::string("two ") + what + " are named '" + nameOf(entry) + "'");
    }
  };
  const auto name = [](const auto& entry) { return entry.name; };
  unique(plan.images, name, "images");
  unique(plan.cohorts, name, "cohorts");
  for (const EvaluationCohort& cohort : plan.cohorts)
    for (const EvaluationImage& image : plan.images)
      if (image.name == cohort.name) throw Error(path, "an image and a cohort are both named '" + image.name + "'");
  unique(plan.structures, name, "structures");
  unique(plan.protocols, [](const EvaluationProtocol& p) { return p.clicks.name; }, "protocols");
  unique(plan.splits, name, "splits");
  return plan;
}

std::vector<EvaluationRun> runEvaluation(const EvaluationPlan& plan, const EvaluationOptions& options,
                                         const std::function<void(const EvaluationRun&, int, int)>& done) {
  if (options.jobs < 1 || options.jobs > 64) throw Error("jobs must be in 1..64");
  std::vector<const EvaluationSplit*> splits;
  for (const EvaluationSplit& s : plan.splits)
    if (options.splits.empty() ||
        std::find(options.splits.begin(), options.splits.end(), s.name) != options.splits.end())
      splits.push_back(&s);
  for (const std::string& name : options.splits) {
    bool known = false;
    std::string names;
    for (const EvaluationSplit& s : plan.splits) {
      known = known || s.name == name;
      names += (names.empty() ? "" : ", ") + s.name;
    }
    if (!known) throw UsageError("--split " + name, "the plan has no such split (its splits: " + names + ")");
  }

  // Every input is read or generated once, before any run: an image, its
  // references (one mask per structure) and what its runs record of it.
  struct Input {
    std::string image, subject, split;  // split: empty for a plan's image (every split)
    std::string path;                   // a plan's image's file
    Volume volume;
    std::shared_ptr<const AtlasAffine> atlasAffine;  // for atlas protocols
    std::map<std::string, Mask> references;
    double snr = 0;
    int thickAxis = -1;
    std::string contrast;
  };
  std::vector<Input> inputs;
  auto addReferences = [&](Input& input, const Volume& labels, const std::string& source) {
    for (const EvaluationStructure& s : plan.structures) {
      Mask& mask = input.references[s.name] = selectLabels(labels, s.labels);
      if (mask.count() == 0) throw Error(source, "structure '" + s.name + "' has no voxel with its labels");
    }
  };
  if (!plan.images.empty()) {
    const Volume labels = readLabelMap(plan.reference);
    for (const EvaluationImage& i : plan.images) {
      Input& input = inputs.emplace_back();
      input.image = i.name;
      input.path = i.path;
      input.volume = readVolume(i.path);
      addReferences(input, labels, plan.reference);
      // Scored in physical space, the reference may lie on another grid, but
      // it must lie on the image: else every run fails on clicks outside it.
      for (const auto& [name, mask] : input.references) {
        bool inside = false;
        for (long long offset = 0; offset < mask.geometry.voxelCount() && !inside; ++offset) {
          if (!mask.voxels[offset]) continue;
          const auto [v, j, k] = mask.geometry.voxelAt(offset);
          inside = input.volume.geometry.covers(mask.geometry.toPhysical(Vector3(v, j, k)));
        }
        if (!inside)
          throw Error(plan.reference, "structure '" + name + "' lies wholly outside image '" + i.name + "' (" + i.path +
                                          "): the reference and the image do not overlap in space");
      }
    }
  }
  for (const EvaluationCohort& cohort : plan.cohorts) {
    const Volume image = readVolume(cohort.image), labels = readLabelMap(cohort.labels);
    for (const auto& [split, seeds] : cohort.subjects) {
      bool wanted = false;
      for (const EvaluationSplit* s : splits) wanted = wanted || s->name == split;
      if (!wanted) continue;
      for (const std::uint64_t seed : seeds) {
        Subject subject = makeSubject(image, labels, cohort.settings, seed, {cohort.image, cohort.labels});
        Input& input = inputs.emplace_back();
        input.image = cohort.name;
        input.subject = "s" + std::to_string(seed);
        input.split = split;
        input.snr = subject.draw.snr;
        input.thickAxis = subject.draw.thickAxis.value_or(-1);
        input.contrast = subject.draw.contrast;
        addReferences(input, subject.labels, cohort.name + " subject " + std::to_string(seed));
        input.volume = std::move(subject.image);
      }
    }
  }
  std::filesystem::create_directories(options.landmarkDirectory);

  // Atlas protocols: the atlas read once, each image registered to it once;
  // an image that is the atlas's template has no registration and runs none.
  std::shared_ptr<const Atlas> atlas;
  if (std::any_of(plan.protocols.begin(), plan.protocols.end(), [](const auto& p) { return p.atlas; })) {
    atlas = std::make_shared<const Atlas>(readAtlas(plan.atlasImage, plan.atlasLabels));
    const std::filesystem::path atlasImage = std::filesystem::weakly_canonical(plan.atlasImage);
    for (Input& input : inputs)
      if (input.path.empty() || std::filesystem::weakly_canonical(input.path) != atlasImage)
        input.atlasAffine =
            std::make_shared<const AtlasAffine>(registerAtlasAffine(input.volume, *atlas, plan.parameters.registration));
  }

  struct Job {
    const Input* input;
    const EvaluationStructure* structure;
    const EvaluationProtocol* protocol;
    EvaluationRun run;
  };
  std::vector<Job> jobs;
  for (const EvaluationSplit* split : splits)
    for (const Input& input : inputs) {
      if (!input.split.empty() && input.split != split->name) continue;
      for (const EvaluationStructure& structure : plan.structures) {
        if (!split->structures.empty() && std::find(split->structures.begin(), split->structures.end(),
                                                    structure.name) == split->structures.end())
          continue;
        for (const EvaluationProtocol& protocol : plan.protocols)
          for (unsigned seed : split->seeds) {
            if (protocol.atlas && !input.atlasAffine) continue;
            EvaluationRun run;
            run.split = split->name;
            run.image = input.image;
            run.subject = input.subject;
            run.subjectSnr = input.snr;
            run.subjectThickAxis = input.thickAxis;
            run.subjectContrast = input.contrast;
            run.structure = structure.name;
            run.protocol = protocol.clicks.name;
            run.seed = seed;
            static const char* const kFormats[] = {"mrk.json", "fcsv", "csv"};
            run.format = protocol.format == "rotate" ? kFormats[seed % 3] : protocol.format;
            jobs.push_back({&input, &structure, &protocol, run});
          }
      }
    }
  // A split that runs nothing would read as one measured without a failure.
  for (const EvaluationSplit* split : splits) {
    if (std::any_of(jobs.begin(), jobs.end(), [&](const Job& job) { return job.run.split == split->name; })) continue;
    const bool hasImage = std::any_of(inputs.begin(), inputs.end(), [&](const Input& input) {
      return input.split.empty() || input.split == split->name;
    });
    throw Error(plan.path,
                "split '" + split->name + "' has no run: " +
                    (hasImage ? "its protocols all start from the atlas, and its images are the atlas's template, on "
                                "which an atlas start is not measured"
                              : "no image of the plan and no subject of a cohort is in it"));
  }

  std::vector<EvaluationRun> runs(jobs.size());
  std::atomic<size_t> next{0};
  std::mutex report;
  int finished = 0;
  auto work = [&] {
    for (size_t k = next++; k < jobs.size(); k = next++) {
      const Job& job = jobs[k];
      EvaluationRun run = job.run;
      try {
        run = runOne(plan, job.input->volume, job.input->references.at(job.structure->name), *job.protocol,
                     job.structure->axis, run, options.landmarkDirectory,
                     {atlas, job.structure->labels, job.input->atlasAffine});
      } catch (const std::exception& e) {
        run.error = e.what();
      }
      runs[k] = run;
      std::lock_guard<std::mutex> lock(report);
      ++finished;
      if (done) done(run, finished, static_cast<int>(jobs.size()));
    }
  };
  std::vector<std::thread> workers;
  for (int t = 1; t < options.jobs; ++t) workers.emplace_back(work);
  work();
  for (std::thread& w : workers) w.join();
  return runs;
}

}  // namespace dynsub
