#pragma once
// Reading numbers from the fields of text files (point clouds, springs,
// landmarks), and naming the nearest of known words for a misspelt one.
#include <string>
#include <vector>

namespace dynsub {

// True when the whole of `field` is a decimal number (as std::stod reads it,
// but not hexadecimal; "nan" and "inf" included: callers decide about
// finiteness); `value` receives it.
bool parseNumber(const std::string& field, double& value);

// Every item of `text` between `separator`s, as written, the empty ones too
// ("71," is "71" and "", where std::getline would give "71" alone); one
// empty item for an empty text.
std::vector<std::string> splitItems(const std::string& text, char separator);

// The fields of a CSV line between `separator`s, as spreadsheets write them:
// a separator inside double quotes does not split ("left, anterior"), the
// quotes and carriage returns are dropped, and each field is trimmed of
// blanks and tabs at its ends.
std::vector<std::string> splitCsvFields(const std::string& line, char separator);

// `text` without the blanks and tabs at its ends.
std::string trimmed(const std::string& text);

// `text` with each line longer than `columns` bytes broken at its last
// space that keeps the first part within them (cut at `columns` where it
// has none, never inside a UTF-8 character), and the break's spaces
// dropped; the spaces within a line stay.
std::string wrapped(const std::string& text, std::size_t columns);

// `items` one after another with `separator` between them (lists in messages).
std::string joined(const std::vector<std::string>& items, const std::string& separator);

// Whether `line` holds nothing to read: it is empty, or blanks, tabs, a CR
// and `separators` alone (a spreadsheet's formatted but empty row).
bool holdsNothing(const std::string& line, const std::string& separators);

// `text` with its ASCII letters in lower case (column names, extensions,
// label names: compared case-insensitively).
std::string lowerCase(std::string text);

// A library's message without the tag it starts with: "[json.exception.
// parse_error.101] parse error at line 1, column 13: ..." -> "parse error at
// line 1, column 13: ...".
std::string withoutLibraryTag(const std::string& message);

// `line` after the object a library's message names by its address
// ("vtkXMLDataParser (0x55d0...): ", "itk::ERROR: NrrdImageIO(0x55d0...): "),
// or as written when it names none.
std::string afterObjectAddress(const std::string& line);

// `line` without the UTF-8 byte order mark that spreadsheets ("CSV UTF-8")
// write before a file's first line.
std::string withoutByteOrderMark(const std::string& line);

// Levenshtein's distance, case-insensitive.
std::size_t editDistance(const std::string& a, const std::string& b);

// The word of `known` nearest to `word` when it is near enough to be a slip
// (at most a third of its letters, and at least one, differ), else empty.
std::string nearestWord(const std::string& word, const std::vector<std::string>& known);

}  // namespace dynsub
