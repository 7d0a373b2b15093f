#pragma once
// Control meshes for tests and benchmarks, chosen to exercise every case of the
// limit surface: extraordinary vertices of valence 3 to 8 inside and on the
// boundary, triangles and n-gons, corners, genus 0 and 1. All are curved (no
// flat patches that would hide errors) and deterministic.
#include <ostream>
#include <string>
#include <vector>

#include "dynsub/ControlMesh.h"

namespace dynsub::testing {

struct NamedMesh {
  std::string name;
  ControlMesh mesh;
};

// n quads around a centre vertex, bent into a bowl. closed = true: the centre
// is an interior extraordinary vertex of valence n; false: the fan is open and
// the centre is a boundary vertex with n faces.
ControlMesh makeFan(int n, bool closed);
// A prism over a regular n-gon: two n-gon caps and n quads (n-gons in the input;
// after isolation their centres are extraordinary vertices of valence n).
ControlMesh makePrism(int n);
// A square pyramid (four triangles and a quad) and a tetrahedron (triangles only).
ControlMesh makePyramid();
ControlMesh makeTetrahedron();
// A bent 3 x 3 grid with one corner quad removed: an L whose inner corner is a
// boundary vertex with 3 faces.
ControlMesh makeLShape();
// The torus with its points moved by a fixed smooth displacement.
ControlMesh makeBumpyTorus();

// Meshes with creases (Topology.h), each of a kind checkCreases accepts:
// infinitely sharp creases that meet at corners or end on boundaries, semi-sharp
// ones of sharpness 0.5 to 2.5 (fractional, decaying at different steps, as
// darts, crossing a sharp crease), on quads, triangles and extraordinary
// vertices. Curved, like the meshes above.
std::vector<NamedMesh> creasedTestMeshes();

// GoogleTest prints a parameter by its name.
inline void PrintTo(const NamedMesh& mesh, std::ostream* out) { *out << mesh.name; }

// Every mesh above plus the standard cube, torus and sheet.
std::vector<NamedMesh> allTestMeshes();

}  // namespace dynsub::testing
