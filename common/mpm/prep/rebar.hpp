#pragma once
/// The scene's [[rebar]] cut into 2-node truss elements whose nodes are particles (004,
/// section 2: HFEMP): straight bars, square-pattern layers and polyline files.
#include <string>
#include <vector>

#include "mpm/core/columns.hpp"
#include "mpm/core/types.hpp"
#include "mpm/grid/lattice.hpp"
#include "mpm/scene/scene.hpp"

namespace mpm {

/// What one [[rebar]] entry became.
struct RebarReport {
  std::size_t bars = 0, elements = 0, nodes = 0;
  double length = 0;          ///< m, all its bars
  double mass = 0;            ///< kg, the sum of its nodes' lumped masses
  double exact_mass = 0;      ///< kg, rho A L_total (A halved on a symmetry plane)
  double element_length = 0;  ///< m, the longest element
  double shortest = 0;        ///< m, the shortest element
};

/// The lines of one [[rebar]] entry, each a polyline of at least two points (m): a bar's two
/// ends, a layer's bars across the body's bounding box (clipped to the domain), or the
/// polylines of a file (x y z in metres per line, '#' comments, a blank line between two
/// polylines). `lo`, `hi`: the body's bounding box. Throws InputError naming the scene's file,
/// line and key (or the polyline file and its line) for a file it cannot read or parse.
std::vector<std::vector<Vec3>> rebar_lines(const Scene& scene, std::size_t entry, const Vec3& lo,
                                           const Vec3& hi, const Lattice& lattice);

/// Cuts every [[rebar]] entry into elements at most its element_length long (default half the
/// cell) and appends their nodes to the model's particle columns `cols` (ids after the largest
/// there; material kRebarNode; the body's initial velocity; lumped mass rho A L / 2 from each
/// element, summed where elements share a node). Returns the element table
/// (rebar_elements.hpp) and fills `report`, one per entry. Throws InputError (file, line and
/// key) for a bar that leaves the domain.
ColumnStore discretise_rebar(const Scene& scene, const Lattice& lattice,
                             const std::vector<Vec3>& body_lo, const std::vector<Vec3>& body_hi,
                             ColumnStore& cols, std::vector<RebarReport>& report);

}  // namespace mpm
