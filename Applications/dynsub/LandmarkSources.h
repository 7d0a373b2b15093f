#pragma once
// The structures that landmark files hold, as `dynsub segment --landmarks`
// and the 3D Slicer module read them: a file's point list is one structure,
// and a 3D Slicer markups file may hold one list per structure.
#include <memory>
#include <string>
#include <vector>

#include "dynsub/Atlas.h"
#include "dynsub/Landmarks.h"
#include "dynsub/SegmentStructures.h"

namespace dynsub::app {

struct LandmarkSource {
  std::string path;  // the file
  std::string name;  // the structure's name without --name (a folder's name: isNameCharacter's)
  LandmarkList list;
};

// A landmark file's name without its folder and extension: caudate_left
// for caudate_left.mrk.json.
std::string structureName(const std::string& path);

// Text as a structure's name: the characters a name may not hold
// (isNameCharacter) made '_' ("Caudate L" -> Caudate_L).
std::string asStructureName(const std::string& text);

// The files' lists, in order. A file of one list gives its stem as the
// name; of several, each list's own name, or the stem and the list's number
// when it has none; each made a structure's name (asStructureName). Throws as readLandmarkLists.
std::vector<LandmarkSource> landmarkSources(const std::vector<std::string>& files);

// Structures of `image` to segment together: the landmark lists, or, with an
// atlas, its labels (atlasLabelValues's form), each paired with the list of
// the same place when there are lists (the caller checks that the counts
// agree). A structure is named by its list, else by the atlas
// (atlasStructureName, made a structure's name). Throws as atlasLabelValues,
// naming `atlasOption`, the flag the labels came from.
std::vector<StructureInputs> structuresToSegment(const std::string& image, const std::vector<LandmarkSource>& sources,
                                                 const std::shared_ptr<const Atlas>& atlas,
                                                 const std::vector<std::string>& atlasLabels,
                                                 const std::string& atlasOption);

}  // namespace dynsub::app
