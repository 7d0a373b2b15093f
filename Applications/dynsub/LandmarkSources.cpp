#include "LandmarkSources.h"

#include <algorithm>
#include <filesystem>

#include "dynsub/FileNames.h"
#include "dynsub/SegmentStructures.h"
#include "dynsub/TextFields.h"

namespace dynsub::app {

std::string structureName(const std::string& path) {
  std::filesystem::path stem = std::filesystem::path(path).stem();
  if (lowerCaseExtension(stem.string()) == ".mrk") stem = stem.stem();
  return stem.string();
}

std::string asStructureName(const std::string& text) {
  std::string name = text;
  std::replace_if(
      name.begin(), name.end(), [](char c) { return !isNameCharacter(c); }, '_');
  return name;
}

std::vector<LandmarkSource> landmarkSources(const std::vector<std::string>& files) {
  std::vector<LandmarkSource> sources;
  for (const std::string& path : files) {
    std::vector<LandmarkList> lists = readLandmarkLists(path);
    for (std::size_t k = 0; k < lists.size(); ++k) {
      // A name of blanks alone names nothing.
      lists[k].name = trimmed(lists[k].name);
      LandmarkSource source;
      source.path = path;
      if (lists.size() == 1)
        source.name = asStructureName(structureName(path));
      else if (lists[k].name.empty())
        source.name = asStructureName(structureName(path)) + "_" + std::to_string(k + 1);
      else
        source.name = asStructureName(lists[k].name);
      source.list = std::move(lists[k]);
      sources.push_back(std::move(source));
    }
  }
  return sources;
}

std::vector<StructureInputs> structuresToSegment(const std::string& image, const std::vector<LandmarkSource>& sources,
                                                 const std::shared_ptr<const Atlas>& atlas,
                                                 const std::vector<std::string>& atlasLabels,
                                                 const std::string& atlasOption) {
  const std::size_t n = atlas ? atlasLabels.size() : sources.size();
  std::vector<StructureInputs> structures;
  for (std::size_t s = 0; s < n; ++s) {
    StructureInputs structure;
    SegmentInputs& in = structure.inputs;
    in.image = image;
    if (!sources.empty()) {
      structure.name = sources[s].name;
      in.landmarkSource = sources[s].path;
      in.landmarks = sources[s].list.landmarks;
      in.landmarkSystem = sources[s].list.stated;
    }
    if (atlas) {
      in.start = parseSegmentStart("atlas", "--init");
      in.atlas = atlas;
      in.atlasLabels = atlasLabelValues(*atlas, atlasLabels[s], atlasOption);
      if (sources.empty()) structure.name = asStructureName(atlasStructureName(*atlas, in.atlasLabels, atlasLabels[s]));
    }
    structures.push_back(std::move(structure));
  }
  return structures;
}

}  // namespace dynsub::app
