#include "dynsub/Lattice.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <set>

#include "dynsub/Error.h"
#include "dynsub/PolygonArea.h"

namespace dynsub {

namespace {

std::vector<int> sortedUnique(std::vector<int> v) {
  std::sort(v.begin(), v.end());
  v.erase(std::unique(v.begin(), v.end()), v.end());
  return v;
}

// The volume the closed shell `shell` of faces encloses, by the divergence
// theorem with its faces oriented alike: each edge run once each way, which
// the first face's orientation fixes up to sign. NaN when no such orientation
// exists (a shell like a Klein bottle's).
double enclosedVolume(const MatrixX3& points, const std::vector<std::vector<int>>& faces,
                      const std::vector<std::vector<int>>& faceEdges, const std::vector<int>& shell) {
  // Each run of an edge by one of the shell's faces: the edge, the face (its
  // place in the shell), and whether it runs from the lower-numbered point.
  // The shell is closed, so sorted by edge they come in pairs.
  std::vector<std::array<int, 3>> runs;
  for (std::size_t k = 0; k < shell.size(); ++k) {
    const std::vector<int>& loop = faces[shell[k]];
    for (std::size_t i = 0; i < loop.size(); ++i)
      runs.push_back({faceEdges[shell[k]][i], static_cast<int>(k), loop[i] < loop[(i + 1) % loop.size()] ? 1 : 0});
  }
  std::sort(runs.begin(), runs.end());
  std::vector<int> sign(shell.size(), 0);
  sign[0] = 1;
  // Faces alike run their shared edge opposite ways. A few passes reach every
  // face of a cell.
  for (bool changed = true; changed;) {
    changed = false;
    for (std::size_t r = 0; r + 1 < runs.size(); r += 2) {
      const int a = runs[r][1], b = runs[r + 1][1];
      const int relation = runs[r][2] != runs[r + 1][2] ? 1 : -1;  // sign[b] = relation * sign[a]
      if (sign[a] != 0 && sign[b] != 0) {
        if (sign[b] != relation * sign[a]) return std::numeric_limits<double>::quiet_NaN();
      } else if (sign[a] != 0 || sign[b] != 0) {
        if (sign[a] == 0)
          sign[a] = relation * sign[b];
        else
          sign[b] = relation * sign[a];
        changed = true;
      }
    }
  }
  // Each face's cone from the origin: its first point dotted with its Newell
  // normal is six times the cone's signed volume (the normal's two terms at
  // that point are perpendicular to it, which leaves the face's fan).
  double sixTimes = 0;
  for (std::size_t k = 0; k < shell.size(); ++k) {
    const std::vector<int>& loop = faces[shell[k]];
    sixTimes += sign[k] * Vector3(points.row(loop[0]).transpose()).dot(newellNormal(points, loop));
  }
  return std::abs(sixTimes) / 6;
}

}  // namespace

Vector3 centroidOf(const MatrixX3& points, const std::vector<int>& indices) {
  Vector3 sum = Vector3::Zero();
  for (int p : indices) sum += points.row(p).transpose();
  return sum / static_cast<double>(indices.size());
}

Lattice Lattice::fromCells(MatrixX3 points, std::vector<std::vector<int>> faces, std::vector<std::vector<int>> cells,
                           const std::string& source) {
  if (points.rows() == 0 || cells.empty()) throw Error(source, "the lattice has no points or no cells");
  if (!points.allFinite()) throw Error(source, "a point has a non-finite coordinate");
  const int n = static_cast<int>(points.rows());
  // A face of no area has no normal to extrude along and makes a cell of no
  // volume; judged as MeshCheck judges a control mesh's faces.
  const double minimumArea = degenerateArea(points);
  // A cell of no volume (its faces folded into one plane) is refused alike,
  // at the same relative scale.
  const double minimumVolume = std::pow(minimumArea, 1.5);
  Lattice l;
  l.points_ = std::move(points);
  l.faces_ = std::move(faces);
  l.cells_ = std::move(cells);
  const int faceCount = l.faceCount();

  std::map<std::pair<int, int>, int> edgeIndex;
  // A face two cells share is listed once: two copies would each be smoothed
  // as a boundary, cutting the solid along it.
  std::map<std::vector<int>, int> loops;
  l.faceEdges_.resize(faceCount);
  for (int f = 0; f < faceCount; ++f) {
    const std::vector<int>& loop = l.faces_[f];
    const std::string name = "face " + std::to_string(f);
    if (loop.size() < 3) throw Error(source, name + " has fewer than 3 points");
    for (int p : loop)
      if (p < 0 || p >= n)
        throw Error(source, name + " uses point " + std::to_string(p) + ", but the lattice has " + std::to_string(n));
    if (sortedUnique(loop).size() != loop.size()) throw Error(source, name + " repeats a point");
    if (const auto [same, added] = loops.try_emplace(sortedUnique(loop), f); !added)
      throw Error(source, name + " has the points of face " + std::to_string(same->second) +
                              ": a face two cells share is listed once, and both cells name it");
    if (const std::string noArea = noAreaReason(l.points_, loop, minimumArea); !noArea.empty())
      throw Error(source, name + " is degenerate: " + noArea);
    for (std::size_t i = 0; i < loop.size(); ++i) {
      const int a = std::min(loop[i], loop[(i + 1) % loop.size()]), b = std::max(loop[i], loop[(i + 1) % loop.size()]);
      auto [it, added] = edgeIndex.try_emplace({a, b}, static_cast<int>(l.edges_.size()));
      if (added) l.edges_.push_back({a, b});
      l.faceEdges_[f].push_back(it->second);
    }
  }

  std::map<std::vector<int>, int> shells;
  l.faceCells_.assign(faceCount, {});
  l.cellEdges_.resize(l.cellCount());
  l.cellPoints_.resize(l.cellCount());
  for (int c = 0; c < l.cellCount(); ++c) {
    const std::string name = "cell " + std::to_string(c);
    const std::vector<int>& shell = l.cells_[c];
    if (shell.size() < 4) throw Error(source, name + " has fewer than 4 faces: it cannot be closed");
    if (sortedUnique(shell).size() != shell.size()) throw Error(source, name + " lists a face twice");
    std::map<int, int> edgeUses;
    for (int f : shell) {
      if (f < 0 || f >= faceCount)
        throw Error(source, name + " uses face " + std::to_string(f) + ", but the lattice has " +
                                std::to_string(faceCount));
      l.faceCells_[f].push_back(c);
      for (int e : l.faceEdges_[f]) ++edgeUses[e];
      l.cellPoints_[c].insert(l.cellPoints_[c].end(), l.faces_[f].begin(), l.faces_[f].end());
    }
    for (const auto& [e, uses] : edgeUses) {
      if (uses != 2)
        throw Error(source, name + " is not closed: its edge " + std::to_string(l.edges_[e][0]) + "-" +
                                std::to_string(l.edges_[e][1]) + " lies in " + std::to_string(uses) +
                                " of its faces (expected 2)");
      l.cellEdges_[c].push_back(e);
    }
    if (const auto [same, added] = shells.try_emplace(sortedUnique(shell), c); !added)
      throw Error(source, name + " has the faces of cell " + std::to_string(same->second));
    // One shell: every face reached from the first across shared edges.
    // Two shells listed as one cell would be subdivided as one solid,
    // bridging the space between them.
    std::map<int, std::vector<int>> edgeFaces;
    for (int f : shell)
      for (int e : l.faceEdges_[f]) edgeFaces[e].push_back(f);
    std::set<int> reached{shell.front()};
    for (std::vector<int> next{shell.front()}; !next.empty();) {
      const int f = next.back();
      next.pop_back();
      for (int e : l.faceEdges_[f])
        for (int g : edgeFaces[e])
          if (reached.insert(g).second) next.push_back(g);
    }
    if (reached.size() != shell.size())
      throw Error(source, name + " is two or more separate shells: a cell is one closed shell (a solid with a cavity "
                              "is cells around it); make each separate solid's shell a cell of its own");
    const double volume = enclosedVolume(l.points_, l.faces_, l.faceEdges_, shell);
    if (std::isnan(volume))
      throw Error(source, name + "'s faces cannot be oriented alike: it has no inside and no outside");
    if (!(volume > minimumVolume)) throw Error(source, name + " is flat: it encloses no volume");
    l.cellPoints_[c] = sortedUnique(l.cellPoints_[c]);
  }
  for (int f = 0; f < faceCount; ++f) {
    if (l.faceCells_[f].empty()) throw Error(source, "face " + std::to_string(f) + " dangles: no cell uses it");
    if (l.faceCells_[f].size() > 2)
      throw Error(source, "face " + std::to_string(f) + " is shared by " + std::to_string(l.faceCells_[f].size()) +
                              " cells (at most 2)");
  }

  l.edgeFaces_.assign(l.edgeCount(), {});
  l.edgeCells_.assign(l.edgeCount(), {});
  l.pointEdges_.assign(n, {});
  l.pointFaces_.assign(n, {});
  l.pointCells_.assign(n, {});
  for (int e = 0; e < l.edgeCount(); ++e)
    for (int p : l.edges_[e]) l.pointEdges_[p].push_back(e);
  for (int f = 0; f < faceCount; ++f) {
    for (int e : l.faceEdges_[f]) l.edgeFaces_[e].push_back(f);
    for (int p : l.faces_[f]) l.pointFaces_[p].push_back(f);
  }
  for (int c = 0; c < l.cellCount(); ++c) {
    for (int e : l.cellEdges_[c]) l.edgeCells_[e].push_back(c);
    for (int p : l.cellPoints_[c]) l.pointCells_[p].push_back(c);
  }
  for (int p = 0; p < n; ++p)
    if (l.pointCells_[p].empty()) throw Error(source, "point " + std::to_string(p) + " belongs to no cell");
  return l;
}

void Lattice::setPoints(const MatrixX3& points) {
  if (points.rows() != points_.rows() || !points.allFinite())
    throw Error("the lattice's new points must be " + std::to_string(points_.rows()) + " finite points");
  points_ = points;
}

int Lattice::edgeBetween(int a, int b) const {
  for (int e : pointEdges_[a])
    if (edges_[e][0] == std::min(a, b) && edges_[e][1] == std::max(a, b)) return e;
  return -1;
}

Lattice extrudeFace(const Lattice& l, int face) {
  if (face < 0 || face >= l.faceCount()) throw Error("no face " + std::to_string(face) + " to extrude");
  if (!l.isBoundaryFace(face))
    throw Error("face " + std::to_string(face) + " is inside the solid: only boundary faces can be extruded");
  const std::vector<int>& loop = l.faces()[face];
  const int cell = l.faceCells()[face][0];
  const Vector3 centroid = centroidOf(l.points(), loop), cellCentroid = centroidOf(l.points(), l.cellPoints()[cell]);
  Vector3 normal = newellNormal(l.points(), loop);
  if (!(normal.norm() > 0)) throw Error("face " + std::to_string(face) + " is degenerate: it has no normal");
  normal.normalize();
  // The new faces run as the extruded face does (counter-clockwise seen from
  // outside, or not), so the boundary stays oriented as it was.
  const bool outward = normal.dot(centroid - cellCentroid) >= 0;
  if (!outward) normal = -normal;
  const double height = 2.0 * std::abs(normal.dot(centroid - cellCentroid));

  const int n = l.pointCount(), k = static_cast<int>(loop.size());
  MatrixX3 points(n + k, 3);
  points.topRows(n) = l.points();
  for (int i = 0; i < k; ++i) points.row(n + i) = l.points().row(loop[i]) + height * normal.transpose();
  std::vector<std::vector<int>> faces = l.faces(), cells = l.cells();
  std::vector<int> shell{face};
  std::vector<int> top;
  for (int i = 0; i < k; ++i) top.push_back(n + i);
  if (!outward) std::reverse(top.begin(), top.end());
  shell.push_back(static_cast<int>(faces.size()));
  faces.push_back(top);
  for (int i = 0; i < k; ++i) {
    const int j = (i + 1) % k;
    std::vector<int> side{loop[i], loop[j], n + j, n + i};
    if (!outward) std::reverse(side.begin(), side.end());
    shell.push_back(static_cast<int>(faces.size()));
    faces.push_back(side);
  }
  cells.push_back(shell);
  return Lattice::fromCells(std::move(points), std::move(faces), std::move(cells), "extruded lattice");
}

bool facesAwayFrom(const Lattice& l, int face, int cell) {
  const std::vector<int>& loop = l.faces()[face];
  return newellNormal(l.points(), loop).dot(centroidOf(l.points(), loop) - centroidOf(l.points(), l.cellPoints()[cell])) >= 0;
}

Lattice deleteCell(const Lattice& l, int cell, std::vector<int>* kept) {
  if (cell < 0 || cell >= l.cellCount()) throw Error("no cell " + std::to_string(cell) + " to delete");
  if (l.cellCount() == 1) throw Error("cell " + std::to_string(cell) + " is the lattice's last: it cannot be deleted");
  // Faces, then points, still used by the other cells, renumbered in order.
  std::vector<int> faceNumber(l.faceCount(), -1), pointNumber(l.pointCount(), -1);
  std::vector<std::vector<int>> cells;
  for (int c = 0; c < l.cellCount(); ++c)
    if (c != cell)
      for (int f : l.cells()[c]) faceNumber[f] = 0;
  int faces = 0;
  for (int& f : faceNumber)
    if (f == 0) f = faces++;
  std::vector<std::vector<int>> newFaces(faces);
  for (int f = 0; f < l.faceCount(); ++f)
    if (faceNumber[f] >= 0)
      for (int p : l.faces()[f]) pointNumber[p] = 0;
  int points = 0;
  for (int& p : pointNumber)
    if (p == 0) p = points++;
  MatrixX3 newPoints(points, 3);
  for (int p = 0; p < l.pointCount(); ++p)
    if (pointNumber[p] >= 0) newPoints.row(pointNumber[p]) = l.points().row(p);
  for (int f = 0; f < l.faceCount(); ++f) {
    if (faceNumber[f] < 0) continue;
    std::vector<int>& loop = newFaces[faceNumber[f]];
    for (int p : l.faces()[f]) loop.push_back(pointNumber[p]);
    // A face the deleted cell shared comes to the surface: it is turned to
    // run counter-clockwise seen from outside, as boundary faces should.
    const auto& owners = l.faceCells()[f];
    if (owners.size() == 2 && (owners[0] == cell || owners[1] == cell)) {
      const int remaining = owners[0] == cell ? owners[1] : owners[0];
      if (!facesAwayFrom(l, f, remaining)) std::reverse(loop.begin(), loop.end());
    }
  }
  for (int c = 0; c < l.cellCount(); ++c) {
    if (c == cell) continue;
    cells.emplace_back();
    for (int f : l.cells()[c]) cells.back().push_back(faceNumber[f]);
  }
  if (kept) *kept = pointNumber;
  return Lattice::fromCells(std::move(newPoints), std::move(newFaces), std::move(cells), "lattice");
}

Lattice regularLattice(int nx, int ny, int nz, double size, const std::vector<int>& removed) {
  if (nx < 1 || ny < 1 || nz < 1) throw Error("a regular lattice needs at least one cell along each axis");
  const int px = nx + 1, py = ny + 1, pz = nz + 1;
  auto point = [&](int i, int j, int k) { return i + px * (j + py * k); };
  MatrixX3 points(px * py * pz, 3);
  for (int k = 0; k < pz; ++k)
    for (int j = 0; j < py; ++j)
      for (int i = 0; i < px; ++i) points.row(point(i, j, k)) << i * size, j * size, k * size;
  const std::set<int> gone(removed.begin(), removed.end());
  // Faces keyed by their sorted points, so neighbouring cells share them.
  std::map<std::vector<int>, int> faceIndex;
  std::vector<std::vector<int>> faces, cells;
  auto face = [&](std::vector<int> loop) {
    std::vector<int> key = loop;
    std::sort(key.begin(), key.end());
    auto [it, added] = faceIndex.try_emplace(key, static_cast<int>(faces.size()));
    if (added) faces.push_back(std::move(loop));
    return it->second;
  };
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) {
        if (gone.count(i + nx * (j + ny * k))) continue;
        const int p000 = point(i, j, k), p100 = point(i + 1, j, k), p010 = point(i, j + 1, k),
                  p110 = point(i + 1, j + 1, k), p001 = point(i, j, k + 1), p101 = point(i + 1, j, k + 1),
                  p011 = point(i, j + 1, k + 1), p111 = point(i + 1, j + 1, k + 1);
        // Loops ordered outward (right-handed about the outward normal).
        cells.push_back({face({p000, p010, p110, p100}), face({p001, p101, p111, p011}),
                         face({p000, p100, p101, p001}), face({p010, p011, p111, p110}),
                         face({p000, p001, p011, p010}), face({p100, p110, p111, p101})});
      }
  // Points no cell uses are dropped, and the rest renumbered.
  std::vector<int> renumber(points.rows(), -1);
  for (const auto& loop : faces)
    for (int p : loop) renumber[p] = 0;
  int used = 0;
  for (int& r : renumber)
    if (r == 0) r = used++;
  MatrixX3 kept(used, 3);
  for (int p = 0; p < points.rows(); ++p)
    if (renumber[p] >= 0) kept.row(renumber[p]) = points.row(p);
  for (auto& loop : faces)
    for (int& p : loop) p = renumber[p];
  return Lattice::fromCells(std::move(kept), std::move(faces), std::move(cells), "regular lattice");
}

}  // namespace dynsub
