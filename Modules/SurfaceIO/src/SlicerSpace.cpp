#include "SlicerSpace.h"

#include <cctype>
#include <fstream>
#include <sstream>

#include <vtkFieldData.h>
#include <vtkPolyData.h>
#include <vtkStringArray.h>

#include "dynsub/FileNames.h"

namespace dynsub {

std::string statedSpace(const std::string& text) {
  for (std::size_t at = text.find("SPACE="); at != std::string::npos; at = text.find("SPACE=", at + 1)) {
    if (at > 0 && (std::isalnum(static_cast<unsigned char>(text[at - 1])) || text[at - 1] == '_')) continue;
    const std::string space = text.substr(at + 6, 3);
    const std::size_t end = at + 9;
    const bool whole = end >= text.size() || !(std::isalnum(static_cast<unsigned char>(text[end])) || text[end] == '_');
    if ((space == "RAS" || space == "LPS") && whole) return space;
  }
  return "";
}

std::string commentSpace(const std::string& path) {
  const std::string extension = lowerCaseExtension(path);
  if (extension != ".ply" && extension != ".obj") return "";
  // A binary PLY's header is text up to end_header; an OBJ's comments come
  // before its first record.
  std::ifstream in(path, std::ios::binary);
  std::string line;
  for (int number = 0; number < 1000 && std::getline(in, line); ++number) {
    std::string word;
    if (!(std::istringstream(line) >> word)) continue;
    if (extension == ".obj" && word[0] != '#') break;
    if (extension == ".ply" && word == "end_header") break;
    if (extension == ".obj" || word == "comment" || word == "obj_info")
      if (const std::string space = statedSpace(line); !space.empty()) return space;
  }
  return "";
}

std::string fieldSpace(vtkPolyData* polyData) {
  if (auto* array = vtkStringArray::SafeDownCast(polyData->GetFieldData()->GetAbstractArray("SPACE")))
    if (array->GetNumberOfValues() > 0) return statedSpace("SPACE=" + array->GetValue(0));
  return "";
}

}  // namespace dynsub
