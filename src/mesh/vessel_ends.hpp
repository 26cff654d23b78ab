#pragma once
// Open and capped vessel ends for CFD (VMTK's and SimVascular's conventions): each tree's inlet
// (its root vessel) and every outlet (leaf) is cut by the plane through its end node
// perpendicular to its vessel, optionally after a straight flow extension of `extension` radii.
// The mesher contours the tree with every end prolonged beyond its plane (so the surface crosses
// the plane as a clean tube); the cut then removes the prolongation, leaving one boundary loop
// exactly in the plane per end (open mode) or filling it with a planar cap (capped mode). Faces
// are labelled: 0 the wall, k + 1 the cap of end k.
#include <cstdint>
#include <string>
#include <vector>

#include "core/vascular_tree.hpp"
#include "mesh/vessel_surface.hpp"

namespace angiosynth {

struct VesselEnd {
  std::int32_t vessel = -1;  // the segment (its distal node id) whose end this is
  std::int32_t tree = 0;
  bool root = false;                 // the tree's root end (else a leaf)
  Vec3 node;                         // the end node of the vessel, mm
  Vec3 centre;                       // the cut plane's point on the axis (node + normal × extension), mm
  Vec3 normal;                       // unit, pointing out of the vessel
  double radius = 0;                 // the vessel's radius at that end, mm
  bool open = false;                 // never capped (a tube's cut, joined to its rings later)
  bool tight = false;                // read only a step around the tube (the caller keeps other vessels out of it)
  double step = 0;                   // tight: that step (mm), else each vertex's own
  double extension_radii = 0;        // the flow extension it got: the one asked, or less where that would reach another vessel
  std::int32_t extension_stop = -1;  // then the vessel (its distal node id) that stopped it
};

// The space an end's cut reads around its axis: from `before` behind its plane to `beyond` past
// it, within `reach` of the axis (mm), for an end of radius r where the contour's step is `step`.
// A vertex of another vessel inside it leaves the end closed. A tight end reads a step around
// its tube; an ordinary one a radius more, since its neighbours are wherever growth put them.
struct EndCutExtent {
  double before, beyond, reach;
};
EndCutExtent endCutExtent(double radius, double step, bool tight = false);

// The open ends of a tree: each root with a single vessel leaving it and every leaf; per tree,
// the root first, then the leaves by position (x, y, z); `extension_radii` ≥ 0 moves each plane
// that many radii beyond its node. An extension is added geometry: where what it adds would
// come within its cut's reach (endCutExtent, for a contour step of `step_radii` of the end's
// radius) of another vessel or of an extension decided before it, it is shortened to the
// longest of 16 lengths that does not (one that starts that near a vessel it diverges from may
// go on while its wall stays more than a step from that vessel's).
std::vector<VesselEnd> openEnds(const VascularTree& t, double extension_radii, double step_radii = 1);

// The tree with every end prolonged along its axis at its end radius, a radius past its plane
// (what the cut removes again).
VascularTree prolongEnds(const VascularTree& t, const std::vector<VesselEnd>& ends);

struct EndCutReport {
  std::int64_t cut = 0;                     // ends cut (and capped in capped mode)
  std::vector<std::int32_t> left_closed;    // ends (indices) whose prolongation merged with another vessel: left round
  std::vector<double> cap_area_mm2;         // per end: the cap's area (0 if open or left closed)
  std::vector<std::int32_t> loop_vertices;  // per end: vertices of its boundary loop
};

// Cuts `m` (the surface of prolongEnds' tree) at every end's plane; `caps` fills each loop (of an
// end not `open`) with a fan of triangles from the plane's centre (the loop is checked to be
// star-shaped around it, else its ears are clipped).
// Sets m.triangle_face. Vertices no triangle uses any more are dropped.
EndCutReport cutEnds(SurfaceMesh& m, const std::vector<VesselEnd>& ends, bool caps);

}  // namespace angiosynth
