#include "EarlierRuns.h"

#include <algorithm>
#include <fstream>
#include <sstream>

#include "FigureOutputs.h"
#include "dynsub/Error.h"
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

namespace {

// The structures' folders an earlier run of several structures left in
// `dir`: those its dseg.tsv names that hold a report.json.
std::vector<std::string> earlierStructureFolders(const std::filesystem::path& dir) {
  std::vector<std::string> folders;
  std::ifstream table(dir / kJoinedTable);
  std::string line;
  std::getline(table, line);  // the header
  while (std::getline(table, line)) {
    std::stringstream row(line);
    std::string index, name;
    if (!std::getline(row, index, '\t') || !std::getline(row, name, '\t')) continue;
    if (usableStructureName(name) && std::filesystem::is_regular_file(dir / name / kReportFile))
      folders.push_back(name);
  }
  return folders;
}

}  // namespace

void requireInputsOutsideRun(const std::filesystem::path& dir, const std::vector<std::string>& inputs,
                             const std::vector<std::string>& keptFolders) {
  for (const std::string& name : runFiles())
    for (const std::string& input : inputs) requireNotInput((dir / name).string(), input);
  // A folder the run retires goes whole, whatever it holds.
  std::error_code error;
  for (const std::string& folder : earlierStructureFolders(dir)) {
    if (std::find(keptFolders.begin(), keptFolders.end(), folder) != keptFolders.end()) continue;
    const std::filesystem::path retired = std::filesystem::weakly_canonical(dir / folder, error);
    for (const std::string& input : inputs) {
      if (input.empty()) continue;
      const std::filesystem::path path = std::filesystem::weakly_canonical(input, error);
      const auto [end, unused] = std::mismatch(retired.begin(), retired.end(), path.begin(), path.end());
      if (end == retired.end())
        throw UsageError(input, "lies in " + (dir / folder).string() +
                                    ", an earlier run's structure folder that this run removes: give the output "
                                    "another directory");
    }
  }
}

void retireEarlierRun(OutputSet& outputs, const std::filesystem::path& dir,
                      const std::vector<std::string>& keptFolders) {
  for (const std::string& name : runFiles()) outputs.retire(name);
  for (const std::string& folder : earlierStructureFolders(dir))
    if (std::find(keptFolders.begin(), keptFolders.end(), folder) == keptFolders.end()) outputs.retire(folder);
}

}  // namespace dynsub::app
