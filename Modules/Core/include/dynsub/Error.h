#pragma once
// DynSub's exceptions. Every error DynSub reports is an Error (or derives from
// it), and its message is meant for the person running the tool: it names
// the file or value at fault and what was expected, e.g.
// "cube.obj: line 12: face 7 uses vertex 130, but the file has 98 vertices".
#include <stdexcept>
#include <string>

namespace dynsub {

class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& message);
  // "<source>: <message>", the form used for every error about a file.
  Error(const std::string& source, const std::string& message);
};

// An option's value that cannot be used (malformed, or not fitting the other
// options), found after the command line was parsed: the programs exit with 2
// for it, as for the values their parser refuses, and 1 for other errors.
class UsageError : public Error {
 public:
  using Error::Error;
};

// Runs `check` and returns what it returns, an Error it throws rethrown as a
// UsageError: for checks shared with files (a plan's settings) where the
// values checked came from the command line.
template <typename Check>
decltype(auto) asUsageError(Check&& check) {
  try {
    return check();
  } catch (const UsageError&) {
    throw;
  } catch (const Error& error) {
    throw UsageError(error.what());
  }
}

// Runs `run` and returns what it returns, an Error it throws (not a
// UsageError) rethrown as "<source>: <message>": for computations on a file's
// contents whose errors (a divergence, a failed factorization) name no file.
template <typename Run>
decltype(auto) naming(const std::string& source, Run&& run) {
  try {
    return run();
  } catch (const UsageError&) {
    throw;
  } catch (const Error& error) {
    throw Error(source, error.what());
  }
}

// An Error about landmarks given as points (outside the image, on no edge):
// a caller that read them from a file catches it to name the file.
class LandmarkError : public Error {
 public:
  using Error::Error;
};

// Throws Error("<name> must be a finite number >= 0 (got <value>)") unless
// `value` is one: the check of every non-negative option and material value.
void requireFiniteNonNegative(double value, const std::string& name);

}  // namespace dynsub
