#pragma once
// Landmarks: named points in physical LPS mm (ITK's and DICOM's convention),
// read from and written to the files 3D Slicer and spreadsheets use:
//  - 3D Slicer markups JSON (.mrk.json): "coordinateSystem" "LPS" (the
//    default when absent) or "RAS"; every control point whose positionStatus
//    is "defined" (or absent) is read, from every point list ("Fiducial"),
//    curve and closed curve in the file; lines, angles, planes and ROIs are
//    left out.
//  - Legacy 3D Slicer fiducials (.fcsv): the "# CoordinateSystem =" header
//    gives LPS or RAS (also the old 1 = LPS, 0 = RAS); columns id,x,y,z,...,label.
//  - CSV (.csv): a header line naming columns x, y, z (LPS mm) or, as 3D
//    Slicer's markups tables do, l, p, s (LPS) or r, a, s (RAS), and
//    optionally label and defined (0 or false: a point not placed, left
//    out); one point per line; '#' comments before the header.
// RAS -> LPS negates x and y.
#include <string>
#include <vector>

#include "dynsub/Types.h"

namespace dynsub {

enum class CoordinateSystem { LPS, RAS };

struct Landmark {
  std::string label;
  Vector3 position;  // LPS mm
};

// Throws dynsub::Error naming the file for a missing file, an unknown format,
// a malformed entry (with its line or index), a markup of an unknown type or
// a non-finite coordinate.
// `stated`, when given, receives the system the file says its values are in
// (a CSV's by its columns; of several markups lists, the first's), for messages
// about a file that says one and holds the other.
std::vector<Landmark> readLandmarks(const std::string& path, CoordinateSystem* stated = nullptr);

// A list of landmarks as a file holds it: a .mrk.json's markup (3D Slicer's
// point list, curve or closed curve; its lines, angles, planes and ROIs are
// left out), or all of a .fcsv or .csv.
struct LandmarkList {
  std::string name;  // the markup's "name"; empty when it has none, and for .fcsv and .csv
  CoordinateSystem stated = CoordinateSystem::LPS;  // the system the file says its values are in
  std::vector<Landmark> landmarks;                  // LPS mm
};
// The file's lists, in order (one list for .fcsv and .csv; the first list
// when none holds a point): a markups file may hold one list per structure.
// Throws as readLandmarks, and for an empty list beside two or more lists
// with points (an empty list beside one is left out).
std::vector<LandmarkList> readLandmarkLists(const std::string& path);

// Format by extension (.mrk.json, .fcsv, .csv); `system` applies to .mrk.json
// and .fcsv (CSV is always LPS). The file appears complete or not at all.
void writeLandmarks(const std::vector<Landmark>& landmarks, const std::string& path,
                    CoordinateSystem system = CoordinateSystem::LPS);

// Writes `landmarks` in place of the one list of points in the file `path`,
// keeping what else the file holds, so that a file 3D Slicer wrote goes back
// to Slicer whole: a .mrk.json's other markups, the list's name, display
// (colour), coordinate system and measurements, and the names Slicer lists
// but has not placed (after the placed points); a point whose label is
// unchanged keeps its id, description and flags. A .fcsv keeps its
// coordinate system; a .csv is written as writeLandmarks writes one (x, y,
// z in LPS). A file that does not exist is written as writeLandmarks writes
// it (LPS).
// Throws dynsub::Error naming the file as readLandmarks does, and for a file
// with more than one list of points.
void updateLandmarks(const std::vector<Landmark>& landmarks, const std::string& path);

// Positions as an N x 3 matrix.
MatrixX3 landmarkPositions(const std::vector<Landmark>& landmarks);

}  // namespace dynsub
