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
    if (number == 1) line = withoutByteOrderMark(line);
    const size_t comment = line.find('#');
    if (comment != std::string::npos) line.erase(comment);
    if (!line.empty() && line.back() == '\r') line.pop_back();  // CR LF line ends
    // One separator per line: semicolons, else commas, else blanks. Read
    // item by item, a decimal comma ("0,5 1 2", or "0,5;1;2") is refused
    // rather than split into two values that shift the rest.
    const char separator = line.find(';') != std::string::npos ? ';' : line.find(',') != std::string::npos ? ',' : 0;
    if (holdsNothing(line, separator ? std::string(1, separator) : std::string())) continue;
    std::vector<std::string> items;
    if (separator) {
      items = splitItems(line, separator);
      // Separators that end the row add no value.
      while (items.size() > 1 && trimmed(items.back()).empty()) items.pop_back();
    } else {
      std::istringstream fields(line);
      for (std::string field; fields >> field;) items.push_back(field);
    }
    std::vector<double> values;
    for (const std::string& item : items) {
      const std::string field = trimmed(item);
      if (field.empty())
        throw Error(path, "line " + std::to_string(number) + ": an empty value (two separators with none between)");
      double value = 0;
      if (!parseNumber(field, value))
        throw Error(path, "line " + std::to_string(number) + ": '" + field +
                              "' is not a number (values are separated by blanks, or by commas, or by semicolons, one "
                              "kind per line, with a decimal point)");
      values.push_back(value);
    }
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
