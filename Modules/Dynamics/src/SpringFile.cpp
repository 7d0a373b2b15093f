#include "dynsub/SpringFile.h"

#include <fstream>
#include <sstream>
#include <vector>

#include "dynsub/Coordinates.h"
#include "dynsub/Error.h"
#include "dynsub/FileNames.h"
#include "dynsub/TextFields.h"

namespace dynsub {

SpringFile readSpringFile(const std::string& path, double defaultStiffness) {
  std::ifstream in = openForReading(path);
  std::vector<Eigen::Vector4d> rows;
  std::string line;
  int number = 0;
  while (std::getline(in, line)) {
    ++number;
    const size_t comment = line.find('#');
    if (comment != std::string::npos) line.erase(comment);
    for (char& c : line) {
      if (c == ',' || c == ';' || c == '\t' || c == '\r') c = ' ';
    }
    std::istringstream fields(line);
    std::vector<double> values;
    std::string field;
    while (fields >> field) {
      double value = 0;
      if (!parseNumber(field, value))
        throw Error(path, "line " + std::to_string(number) + ": '" + field + "' is not a number");
      values.push_back(value);
    }
    if (values.empty()) continue;
    if (values.size() != 3 && values.size() != 4) {
      throw Error(path, "line " + std::to_string(number) + ": expected x y z or x y z stiffness");
    }
    const Eigen::Vector4d row(values[0], values[1], values[2], values.size() == 4 ? values[3] : defaultStiffness);
    if (!row.allFinite()) throw Error(path, "line " + std::to_string(number) + ": a value is not finite");
    const std::string at = "line " + std::to_string(number) + ": ";
    if (!(row(3) > 0.0 && row(3) <= kLargestSpringStiffness)) {
      std::ostringstream text;
      text << "stiffness " << row(3) << " is outside (0, " << kLargestSpringStiffness << "] N/mm";
      throw Error(path, at + text.str());
    }
    const std::string beyond = beyondLargestCoordinate(row.head<3>());
    if (!beyond.empty()) throw Error(path, at + "the spring's point " + beyond);
    rows.push_back(row);
  }
  if (rows.empty()) throw Error(path, "has no springs");
  SpringFile result{MatrixX3(rows.size(), 3), Eigen::VectorXd(rows.size())};
  for (size_t i = 0; i < rows.size(); ++i) {
    result.targets.row(i) = rows[i].head<3>().transpose();
    result.stiffness(i) = rows[i](3);
  }
  return result;
}

}  // namespace dynsub
