#include "LandmarkSources.h"

#include <algorithm>
#include <filesystem>

#include "dynsub/FileNames.h"
#include "dynsub/SegmentStructures.h"

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

}  // namespace dynsub::app
