#pragma once
// A run of `fit`, `deform`, `segment` or `solid sculpt` leaves only its own
// outputs in its directory. What an earlier run of any of them wrote there
// that this run does not (a segmentation's labelmap beside a fit's surface,
// a fit's outliers or figures beside a deformed surface, the folders of
// structures segmented together, a sculpture's figure after a run without
// one) would read as this run's, so the run retires it (OutputSet::retire).
// A file or folder of the user's that none of them writes is never touched.
#include <filesystem>
#include <string>
#include <vector>

namespace dynsub {
class OutputSet;
}

namespace dynsub::app {

// The files these commands may write besides writeModelOutputs's (ModelOutputs.h).
constexpr char kLabelmapFile[] = "labelmap.nii.gz";  // a segmented structure's
constexpr char kJoinedLabelmap[] = "dseg.nii.gz";    // structures segmented together, with
constexpr char kJoinedTable[] = "dseg.tsv";          // their names and label values
// The points a fit set aside (.xyz, exact doubles: `render --outliers` matches them against the scan).
constexpr char kOutliersFile[] = "outliers.xyz";
// A sculpted solid: its control lattice, its subdivided solid and its figure.
constexpr char kSculptedLattice[] = "sculpted.lattice";
constexpr char kSculptedSolid[] = "sculpted.vtu";
constexpr char kSculptedFigure[] = "sculpted.png";

// Every file a run of these commands may write in its directory: the model's
// files, the ones above, convergence.csv and the figures in each format.
std::vector<std::string> runFiles();

// Throws UsageError when one of `inputs` is a file of runFiles() in `dir`,
// or lies in a structure's folder that retireEarlierRun would remove (those
// not in `keptFolders`): the run would overwrite it or remove it.
void requireInputsOutsideRun(const std::filesystem::path& dir, const std::vector<std::string>& inputs,
                             const std::vector<std::string>& keptFolders = {});

// Retires every file of runFiles() in `dir` (the set keeps those it
// writes itself), and the structures' folders an earlier run of several
// structures left there but those named in `keptFolders`: the folders its
// dseg.tsv names that hold a report.json.
void retireEarlierRun(OutputSet& outputs, const std::filesystem::path& dir,
                      const std::vector<std::string>& keptFolders = {});

}  // namespace dynsub::app
