#include "EarlierRuns.h"

#include <algorithm>
#include <fstream>
#include <sstream>

#include "FigureOutputs.h"
#include "dynsub/FileNames.h"
#include "dynsub/ModelOutputs.h"
#include "dynsub/OutputSet.h"
#include "dynsub/SegmentStructures.h"

namespace dynsub::app {

std::vector<std::string> runFiles() {
  std::vector<std::string> names = figureOutputNames();
  names.insert(names.end(), {kSurfaceFile, kControlMeshFile, kReportFile, kLabelmapFile, kJoinedLabelmap, kJoinedTable,
                             kOutliersFile, kSculptedLattice, kSculptedSolid, kSculptedFigure});
  return names;
}

void requireInputsOutsideRun(const std::filesystem::path& dir, const std::vector<std::string>& inputs) {
  for (const std::string& name : runFiles())
    for (const std::string& input : inputs) requireNotInput((dir / name).string(), input);
}

void retireEarlierRun(OutputSet& outputs, const std::filesystem::path& dir,
                      const std::vector<std::string>& keptFolders) {
  for (const std::string& name : runFiles()) outputs.retire(name);
  std::ifstream table(dir / kJoinedTable);
  std::string line;
  std::getline(table, line);  // the header
  while (std::getline(table, line)) {
    std::stringstream row(line);
    std::string index, name;
    if (!std::getline(row, index, '\t') || !std::getline(row, name, '\t')) continue;
    if (!usableStructureName(name) || std::find(keptFolders.begin(), keptFolders.end(), name) != keptFolders.end())
      continue;
    if (std::filesystem::is_regular_file(dir / name / kReportFile)) outputs.retire(name);
  }
}

}  // namespace dynsub::app
