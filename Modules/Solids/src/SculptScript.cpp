#include "dynsub/SculptScript.h"

#include <cmath>
#include <fstream>
#include <sstream>

#include "dynsub/Error.h"
#include "dynsub/FileNames.h"
#include "dynsub/TextFields.h"

namespace dynsub {

namespace {

// The words of one script line, read left to right; a failure names the line.
class Words {
 public:
  Words(std::vector<std::string> words, const std::string& path, int line)
      : words_(std::move(words)), path_(path), line_(line) {}

  [[noreturn]] void fail(const std::string& message) const {
    throw Error(path_, "line " + std::to_string(line_) + ": " + message);
  }
  bool done() const { return next_ >= words_.size(); }
  std::size_t left() const { return words_.size() - next_; }
  const std::string& peek() const { return words_[next_]; }
  void skip() { ++next_; }

  std::string word(const char* what) {
    if (done()) fail(std::string("missing ") + what);
    return words_[next_++];
  }
  double number(const char* what) {
    const std::string w = word(what);
    double value = 0;
    if (!parseNumber(w, value) || !std::isfinite(value)) fail(std::string(what) + " must be a finite number, not '" + w + "'");
    return value;
  }
  double positive(const char* what) {
    const double value = number(what);
    if (!(value > 0)) fail(std::string(what) + " must be > 0");
    return value;
  }
  int index(const char* what, int limit = 100000000) {
    const std::string w = word(what);
    double value = 0;
    if (!parseNumber(w, value) || value != std::floor(value) || value < 0 || value > limit)
      fail(std::string(what) + " must be a whole number from 0 to " + std::to_string(limit) + ", not '" + w + "'");
    return static_cast<int>(value);
  }
  Vector3 point(const char* what) {
    const double x = number(what), y = number(what), z = number(what);
    return Vector3(x, y, z);
  }
  void end() const {
    if (!done()) fail("unexpected '" + words_[next_] + "' at the end of the line");
  }

 private:
  std::vector<std::string> words_;
  std::string path_;
  int line_;
  std::size_t next_ = 0;
};

// "fix ..." and "unfix ...": point indices, "face F" (or "all" to unfix).
std::function<void(Sculpture&)> pointAction(Words& w, bool fix) {
  if (!w.done() && w.peek() == "face") {
    w.skip();
    const int face = w.index("face index");
    w.end();
    return [face, fix](Sculpture& s) {
      const Lattice& l = s.rest();
      if (face >= l.faceCount())
        throw Error("no face " + std::to_string(face) + " (the lattice has " + std::to_string(l.faceCount()) + ")");
      fix ? s.fix(l.faces()[face]) : s.unfix(l.faces()[face]);
    };
  }
  if (!fix && !w.done() && w.peek() == "all") {
    w.skip();
    w.end();
    return [](Sculpture& s) { s.unfixAll(); };
  }
  std::vector<int> points;
  while (!w.done()) points.push_back(w.index("control point index"));
  if (points.empty()) w.fail(std::string("expected control point indices, 'face F'") + (fix ? "" : " or 'all'"));
  return [points, fix](Sculpture& s) { fix ? s.fix(points) : s.unfix(points); };
}

// "extrude F", "extrude at X Y Z", "delete C", "delete at X Y Z".
std::function<void(Sculpture&)> topologyAction(Words& w, bool extrude) {
  if (!w.done() && w.peek() == "at") {
    w.skip();
    const Vector3 at = w.point("coordinate");
    w.end();
    if (extrude) return [at](Sculpture& s) { s.extrude(s.boundaryFaceNear(at)); };
    return [at](Sculpture& s) { s.deleteCell(s.cellNear(at)); };
  }
  const int index = w.index(extrude ? "face index" : "cell index");
  w.end();
  if (extrude) return [index](Sculpture& s) { s.extrude(index); };
  return [index](Sculpture& s) { s.deleteCell(index); };
}

std::function<void(Sculpture&)> parseAction(Words& w) {
  const std::string verb = w.word("action");
  if (verb == "run") {
    const int steps = w.index("step count", 10000000);
    w.end();
    return [steps](Sculpture& s) { s.run(steps); };
  }
  if (verb == "rope") {
    const Vector3 from = w.point("coordinate");
    if (w.word("'to'") != "to") w.fail("expected 'rope X Y Z to TX TY TZ'");
    const Vector3 to = w.point("coordinate");
    w.end();
    return [from, to](Sculpture& s) {
      s.grab(from);
      s.pullTo(to);
    };
  }
  if (verb == "pull") {
    const Vector3 to = w.point("coordinate");
    w.end();
    return [to](Sculpture& s) { s.pullTo(to); };
  }
  if (verb == "release") {
    w.end();
    return [](Sculpture& s) { s.release(); };
  }
  if (verb == "fix" || verb == "unfix") return pointAction(w, verb == "fix");
  if (verb == "extrude" || verb == "delete") return topologyAction(w, verb == "extrude");
  if (verb == "plasticity") {
    w.end();
    return [](Sculpture& s) { s.plasticity(); };
  }
  if (verb == "stiffness") {
    const double k = w.positive("stiffness");
    const double kv = w.done() ? -1 : w.positive("virtual stiffness");
    w.end();
    return [k, kv](Sculpture& s) {
      SolidMaterial m = s.settings().material;
      m.springStiffness = k;
      if (kv > 0) m.virtualStiffness = kv;
      s.setMaterial(m);
    };
  }
  if (verb == "damping") {
    const double g = w.number("damping");
    if (g < 0) w.fail("damping must be >= 0");
    w.end();
    return [g](Sculpture& s) {
      SolidMaterial m = s.settings().material;
      m.damping = g;
      s.setMaterial(m);
    };
  }
  w.fail("unknown action '" + verb +
         "' (expected run, rope, pull, release, fix, unfix, extrude, delete, plasticity, stiffness or damping)");
}

}  // namespace

std::vector<SculptAction> readSculptScript(const std::string& path) {
  std::ifstream in = openForReading(path);
  std::vector<SculptAction> actions;
  std::string text;
  int line = 0;
  while (std::getline(in, text)) {
    ++line;
    if (!text.empty() && text.back() == '\r') text.pop_back();
    std::istringstream fields(text);
    std::vector<std::string> words;
    for (std::string word; fields >> word;) words.push_back(word);
    if (words.empty() || words.front()[0] == '#') continue;
    Words w(std::move(words), path, line);
    const auto first = text.find_first_not_of(" \t");
    actions.push_back({line, text.substr(first), parseAction(w)});
  }
  if (in.bad()) throw Error(path, "could not be read to the end");
  if (actions.empty()) throw Error(path, "the script has no actions");
  return actions;
}

void runSculptScript(const std::vector<SculptAction>& actions, Sculpture& sculpture, const std::string& path,
                     const std::function<void(const SculptAction&)>& done) {
  for (const SculptAction& action : actions) {
    try {
      action.apply(sculpture);
    } catch (const Error& e) {
      throw Error(path, "line " + std::to_string(action.line) + " (" + action.text + "): " + e.what());
    }
    if (done) done(action);
  }
}

}  // namespace dynsub
