#include "dynsub/TextFields.h"

#include <algorithm>
#include <cctype>
#include <sstream>
#include <stdexcept>

namespace dynsub {

bool parseNumber(const std::string& field, double& value) {
  // std::stod reads hexadecimal ("0x1", "0x1p3"), which no file DynSub reads
  // means: a mistyped value.
  if (field.find_first_of("xX") != std::string::npos) return false;
  try {
    std::size_t used = 0;
    value = std::stod(field, &used);
    return used == field.size();
  } catch (const std::logic_error&) {  // invalid_argument, out_of_range
    return false;
  }
}

std::vector<std::string> splitItems(const std::string& text, char separator) {
  std::vector<std::string> items;
  for (std::size_t start = 0; start <= text.size();) {
    const std::size_t end = std::min(text.find(separator, start), text.size());
    items.push_back(text.substr(start, end - start));
    start = end + 1;
  }
  return items;
}

std::vector<std::string> splitCsvFields(const std::string& line, char separator) {
  std::vector<std::string> fields(1);
  bool quoted = false;
  for (const char c : line) {
    if (c == '"')
      quoted = !quoted;
    else if (c == separator && !quoted)
      fields.emplace_back();
    else if (c != '\r')
      fields.back() += c;
  }
  for (std::string& field : fields) field = trimmed(field);
  return fields;
}

std::string trimmed(const std::string& text) {
  const std::size_t first = text.find_first_not_of(" \t");
  return first == std::string::npos ? std::string() : text.substr(first, text.find_last_not_of(" \t") + 1 - first);
}

std::string joined(const std::vector<std::string>& items, const std::string& separator) {
  std::string text;
  for (const std::string& item : items) text += (text.empty() ? "" : separator) + item;
  return text;
}

std::string wrapped(const std::string& text, std::size_t columns) {
  columns = std::max<std::size_t>(columns, 1);
  std::string out, line;
  std::istringstream lines(text);
  bool first = true;
  while (std::getline(lines, line)) {
    if (!first) out += '\n';
    first = false;
    while (line.size() > columns) {
      const std::size_t space = line.rfind(' ', columns);
      std::size_t end = space == std::string::npos || space == 0 ? columns : space;
      // A cut inside a word does not split a UTF-8 character's bytes.
      while (end > 1 && (static_cast<unsigned char>(line[end]) & 0xC0) == 0x80) --end;
      std::size_t kept = end;
      while (kept > 0 && line[kept - 1] == ' ') --kept;
      out += line.substr(0, kept) + '\n';
      const std::size_t next = line.find_first_not_of(' ', end);
      line = next == std::string::npos ? std::string() : line.substr(next);
    }
    out += line;
  }
  return out;
}

std::string withoutLibraryTag(const std::string& message) {
  const std::size_t end = message.find("] ");
  return message.rfind('[', 0) == 0 && end != std::string::npos ? message.substr(end + 2) : message;
}

std::string afterObjectAddress(const std::string& line) {
  const std::size_t address = line.find("(0x");
  const std::size_t end = address == std::string::npos ? std::string::npos : line.find("): ", address);
  return end == std::string::npos ? line : line.substr(end + 3);
}

bool holdsNothing(const std::string& line, const std::string& separators) {
  return line.find_first_not_of(" \t\r" + separators) == std::string::npos;
}

std::string lowerCase(std::string text) {
  for (char& c : text) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return text;
}

std::string withoutByteOrderMark(const std::string& line) {
  return line.rfind("\xEF\xBB\xBF", 0) == 0 ? line.substr(3) : line;
}

std::size_t editDistance(const std::string& a, const std::string& b) {
  const auto lower = [](unsigned char c) { return static_cast<char>(std::tolower(c)); };
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t above = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (lower(a[i - 1]) != lower(b[j - 1]))});
      diagonal = above;
    }
  }
  return row[b.size()];
}

std::string nearestWord(const std::string& word, const std::vector<std::string>& known) {
  std::string nearest;
  std::size_t best = std::max<std::size_t>(1, word.size() / 3) + 1;
  for (const std::string& k : known) {
    const std::size_t d = editDistance(word, k);
    if (d < best) {
      best = d;
      nearest = k;
    }
  }
  return nearest;
}

}  // namespace dynsub
