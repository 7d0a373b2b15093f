#pragma once
// Validity checks on raw polygon data, run before a control mesh is built (a
// halfedge structure cannot even represent most of the defects checked here).
#include <string>
#include <vector>

#include "dynsub/Types.h"

namespace dynsub {

// The most faces around one vertex of a control mesh. The exact limit
// surface and the dynamics' matrices near a vertex of valence n cost time
// growing faster than n^3 (their special elements each span its O(n)
// neighbours): fitting a sphere's 3,000 points from a bipyramid takes 2 s
// at 32 faces around its apexes, 14 s at 64 and 7 minutes at 128.
constexpr int kLargestValence = 64;

// Throws dynsub::Error("<source>: <problem>") for the first problem found:
// no vertices or no faces; a coordinate that is NaN or infinite; a face with
// fewer than 3 vertices, a vertex index out of range, a repeated vertex, or
// (near-)zero area (below 1e-12 of the squared bounding-box diagonal); an
// isolated vertex; an edge with more than two faces (non-manifold edge); a
// vertex whose faces form more than one fan (non-manifold vertex); two faces
// traversing an edge in the same direction (inconsistent orientation); a
// vertex with more than kLargestValence faces around it. The problem names
// vertices and faces as the file counts them, from `firstNumber` (OBJ's
// faces number vertices from 1; OFF and PLY from 0).
void checkPolygonMesh(const MatrixX3& points, const std::vector<std::vector<int>>& faces, const std::string& source,
                      int firstNumber = 0);

class Topology;

// Throws dynsub::Error("<source>: <problem>") for an infinitely sharp crease
// (sharpness >= kInfiniteSharpness) whose limit surface DynSub cannot evaluate
// exactly. It evaluates one by cutting the mesh along such creases into
// pieces with boundaries, which is exact where each vertex on them is
//  - a crease vertex (exactly two sharp edges, boundary edges included) with
//    at least two faces on each side, or
//  - a corner (three or more sharp edges, or a boundary vertex of one face)
//    with one face between each two neighbouring sharp edges.
// Refused: a crease that ends inside the surface (a dart), and the other
// configurations. Semi-sharp creases are refined away before the cut: any
// configuration, up to kLargestSemiSharpness (Topology.h).
void checkCreases(const Topology& topology, const std::string& source);

}  // namespace dynsub
