#pragma once
// Lattice files.
//
// `.lattice` (DynSub's text format; lines starting with # are comments):
//   dynsub-lattice 1
//   points N            then N lines "x y z" (mm)
//   faces F             then F lines "k p1 ... pk" (a loop of k point indices, from 0)
//   cells C             then C lines "m f1 ... fm" (the m faces of a closed cell, from 0)
// Boundary faces are best listed with their points ordered counter-clockwise
// seen from outside (the boundary surface is drawn with that orientation).
//
// `.vtu` (VTK XML unstructured grid, written only): every cell as a
// VTK_POLYHEDRON with its faces, for ParaView and the like.
#include <string>

#include "dynsub/Lattice.h"

namespace dynsub {

// Throws dynsub::Error naming the file and the line for a missing, truncated
// or malformed file, and the element for an invalid lattice (Lattice.h).
Lattice readLattice(const std::string& path);

// By extension: .lattice or .vtu. The file appears complete or not at all.
void writeLattice(const Lattice& lattice, const std::string& path);

// Throws dynsub::Error naming `path` when writeLattice could not write it: an
// extension other than .lattice or .vtu, or a directory that is missing,
// read-only or a file. Commands call it before their work.
void requireLatticeTarget(const std::string& path);

}  // namespace dynsub
