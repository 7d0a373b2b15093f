#pragma once
// Reading numbers from the fields of text files (point clouds, springs,
// landmarks), and naming the nearest of known words for a misspelt one.
#include <string>
#include <vector>

namespace dynsub {

// True when the whole of `field` is a number (as std::stod reads it; "nan" and
// "inf" included: callers decide about finiteness); `value` receives it.
bool parseNumber(const std::string& field, double& value);

// Levenshtein's distance, case-insensitive.
std::size_t editDistance(const std::string& a, const std::string& b);

// The word of `known` nearest to `word` when it is near enough to be a slip
// (at most a third of its letters, and at least one, differ), else empty.
std::string nearestWord(const std::string& word, const std::vector<std::string>& known);

}  // namespace dynsub
