#include "dynsub/Report.h"

#include <fstream>

#include <nlohmann/json.hpp>

#include "dynsub/AtomicOutput.h"
#include "dynsub/Error.h"

namespace dynsub {

struct Report::Impl {
  nlohmann::ordered_json json = nlohmann::ordered_json::object();
};

Report::Report() : impl_(std::make_unique<Impl>()) {}
Report::~Report() = default;
Report::Report(const Report& other) : impl_(std::make_unique<Impl>(*other.impl_)) {}
Report& Report::operator=(const Report& other) {
  *impl_ = *other.impl_;
  return *this;
}
Report::Report(Report&& other) noexcept : impl_(std::move(other.impl_)) {}
Report& Report::operator=(Report&& other) noexcept {
  impl_ = std::move(other.impl_);
  return *this;
}

void Report::set(const std::string& name, int value) { impl_->json[name] = value; }
void Report::set(const std::string& name, long value) { impl_->json[name] = value; }
void Report::set(const std::string& name, std::size_t value) { impl_->json[name] = value; }
void Report::set(const std::string& name, double value) { impl_->json[name] = value; }
void Report::set(const std::string& name, bool value) { impl_->json[name] = value; }
void Report::set(const std::string& name, const std::string& value) { impl_->json[name] = value; }
void Report::set(const std::string& name, const char* value) { impl_->json[name] = value; }
void Report::set(const std::string& name, const Vector3& point) {
  impl_->json[name] = {point.x(), point.y(), point.z()};
}
void Report::set(const std::string& name, const std::array<int, 3>& values) { impl_->json[name] = values; }
void Report::set(const std::string& name, const std::vector<int>& values) { impl_->json[name] = values; }
void Report::set(const std::string& name, const std::vector<double>& values) { impl_->json[name] = values; }
void Report::set(const std::string& name, const std::vector<std::string>& values) { impl_->json[name] = values; }
void Report::set(const std::string& name, const std::vector<Vector3>& points) {
  nlohmann::ordered_json list = nlohmann::ordered_json::array();
  for (const Vector3& p : points) list.push_back({p.x(), p.y(), p.z()});
  impl_->json[name] = std::move(list);
}
void Report::set(const std::string& name, const Report& object) { impl_->json[name] = object.impl_->json; }
void Report::set(const std::string& name, const std::vector<Report>& objects) {
  nlohmann::ordered_json list = nlohmann::ordered_json::array();
  for (const Report& object : objects) list.push_back(object.impl_->json);
  impl_->json[name] = std::move(list);
}

void Report::merge(const Report& other) {
  for (const auto& [name, value] : other.impl_->json.items()) impl_->json[name] = value;
}

std::string Report::text(int indent) const { return impl_->json.dump(indent) + '\n'; }

void Report::write(const std::string& path) const {
  std::ofstream out(path);
  out << text();
  out.close();
  if (!out) throw writeFailure(path);
}

}  // namespace dynsub
