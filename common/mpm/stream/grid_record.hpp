#pragma once
/// The GRID record of a stream: a graded grid's cells and nodes (docs/format.md), written by
/// mpm-prep and mpm-run (GradedGrid::mesh) and read by mpm-post (the grid in ParaView).
#include <cstddef>
#include <cstdint>
#include <vector>

namespace mpm {

/// A graded grid as stored in streams (GRID record, docs/format.md) and shown in ParaView.
struct GridMesh {
  int dim = 3;
  int levels = 1;
  std::int64_t step = 0;
  double time = 0;                      ///< s: the grid holds from this time on
  std::vector<double> x;                ///< node positions, 3 per node (z = 0 in 2D), m
  std::vector<std::uint8_t> level;      ///< per cell: its level, 1 = coarsest
  std::vector<std::uint32_t> corners;   ///< per cell: 2^dim node indices, corner c at bit order
  std::vector<std::uint32_t> mask;      ///< per cell: optional nodes present (transition_shape.hpp)
  std::vector<std::uint32_t> optional;  ///< the present optional nodes, cell after cell
  std::size_t nodes() const { return x.size() / 3; }
  std::size_t cells() const { return level.size(); }
};

/// GRID record payload of a mesh, and back. decode_grid throws StreamError (where empty)
/// when the payload is malformed.
std::vector<std::byte> encode_grid(const GridMesh& mesh);
GridMesh decode_grid(const std::vector<std::byte>& payload);

}  // namespace mpm
