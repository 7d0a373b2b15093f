#pragma once
// The numbers of a run as the JSON files the commands write (report.json,
// the evaluation's summary.json): an object of named values in the order
// they were set, where a value is a number, a string, a boolean, a list of
// them, a point, or another Report. Setting a name again replaces its value
// in place. The JSON library stays behind this type, out of every header.
#include <array>
#include <cstddef>
#include <memory>
#include <string>
#include <vector>

#include "dynsub/Types.h"

namespace dynsub {

class Report {
 public:
  Report();
  ~Report();
  Report(const Report& other);
  Report& operator=(const Report& other);
  Report(Report&& other) noexcept;
  Report& operator=(Report&& other) noexcept;

  // Integers stay integers in the file; `std::size_t` counts are unsigned.
  void set(const std::string& name, int value);
  void set(const std::string& name, long value);  // Eigen::Index
  void set(const std::string& name, std::size_t value);
  void set(const std::string& name, double value);
  void set(const std::string& name, bool value);
  void set(const std::string& name, const std::string& value);
  void set(const std::string& name, const char* value);
  void set(const std::string& name, const Vector3& point);  // [x, y, z]
  void set(const std::string& name, const std::array<int, 3>& values);
  void set(const std::string& name, const std::vector<int>& values);
  void set(const std::string& name, const std::vector<double>& values);
  void set(const std::string& name, const std::vector<std::string>& values);
  void set(const std::string& name, const std::vector<Vector3>& points);  // [[x, y, z], ...]
  void set(const std::string& name, const Report& object);
  void set(const std::string& name, const std::vector<Report>& objects);  // a list, [] when empty
  // Every value of `other`, in its order, as if set one by one.
  void merge(const Report& other);

  // The JSON text with a final newline: indented by `indent` spaces, or on
  // one line for a negative indent.
  std::string text(int indent = 2) const;
  // Writes text() to `path`; throws dynsub::Error naming the file when it cannot.
  void write(const std::string& path) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace dynsub
