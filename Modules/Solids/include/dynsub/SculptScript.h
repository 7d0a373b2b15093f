#pragma once
// Sculpting scripts (`dynsub solid sculpt LATTICE --script FILE`): the tools
// of Sculpting.h as text, one action per line, applied in order. Blank lines
// and lines starting with # are skipped. Points are x y z in mm; indices count
// from 0 and refer to the control lattice as it is when the line runs (extrude
// appends points, faces and cells; delete renumbers, see Lattice.h).
//
//   run N                    N time steps (of the sculpture's time step)
//   rope X Y Z to TX TY TZ   fasten the rope to the mass point nearest (X, Y, Z)
//                            and pull it towards (TX, TY, TZ)
//   pull TX TY TZ            move the rope's free end
//   release                  let go of the rope
//   fix I J ...              fix control points
//   fix face F               fix the points of control face F
//   unfix I J ... | unfix face F | unfix all
//   extrude F                grow a cell on boundary face F
//   extrude at X Y Z         ... on the boundary face whose centre is nearest
//   delete C                 remove cell C
//   delete at X Y Z          ... the cell whose centre is nearest
//   plasticity               the current shape becomes the rest shape
//   stiffness K [KV]         normal springs K, virtual springs KV (N/mm)
//   damping G                N s/mm
#include <functional>
#include <string>
#include <vector>

#include "dynsub/Sculpting.h"

namespace dynsub {

struct SculptAction {
  int line = 0;      // in the script file
  std::string text;  // the line as written
  std::function<void(Sculpture&)> apply;
};

// The whole script is read and checked before any action runs. Throws
// dynsub::Error naming the file and the line for a missing file, an unknown
// action, or a malformed or impossible argument.
std::vector<SculptAction> readSculptScript(const std::string& path);

// Applies the actions in order; `done` (if given) is called after each.
// Throws dynsub::Error naming the file, the line and the action when a tool
// does not apply (an interior face to extrude, an index out of range, a
// diverging simulation).
void runSculptScript(const std::vector<SculptAction>& actions, Sculpture& sculpture, const std::string& path,
                     const std::function<void(const SculptAction&)>& done = nullptr);

}  // namespace dynsub
