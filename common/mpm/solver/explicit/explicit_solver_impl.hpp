#pragma once
// Explicit MPM. The time step is ExplicitSolver::step, right below: a few named kernels whose
// order is the only difference between USF, USL and MUSL. Each kernel is in the file named
// after it (p2g.hpp, grid_update.hpp, g2p.hpp, stress.hpp, graded_split.hpp; the scatters in
// scatter.hpp); with [[contact]] the grid kernels end by exchanging momentum between the
// bodies' velocity fields (contact.hpp). Construction and the reduction of the kernels' sums
// follow the step. Included
// by the translation units that instantiate the solver for a grid type.
#include <omp.h>

#include <algorithm>
#include <cmath>

#include "mpm/solver/explicit/contact.hpp"
#include "mpm/solver/explicit/explicit_solver.hpp"
#include "mpm/solver/explicit/g2p.hpp"
#include "mpm/solver/explicit/graded_split.hpp"
#include "mpm/solver/explicit/grid_update.hpp"
#include "mpm/solver/explicit/p2g.hpp"
#include "mpm/solver/explicit/stress.hpp"

namespace mpm {

template <Grid GridT>
void ExplicitSolver<GridT>::step(double dt) {
  dt_ = dt;
  if (need_sort_) sort_particles();  // cell order; the grid window follows the material
  const double internal_start = balance_.internal;
  switch (scheme_) {
    case Scheme::USF:                           // update stress first (004, section 3.4)
      p2g<kMass | kMomentum>();                 // m_i, p_i (004, eqs. 24-25)
      grid_velocity();                          // v_i = p_i / m_i, boundary conditions
      update_stress(grid_.v, Positions::Stay);  // strain rate, spin, stress (004, eqs. 26-27)
      p2g<kForce>();                            // f_i (004, eqs. 28-29)
      grid_update(NodeV::Velocity);             // p_i += f_i dt (004, eq. 30)
      g2p<G2pMode::Move>();                     // v_p, x_p (004, eqs. 9-10)
      break;
    case Scheme::USL:  // update stress last
      p2g<kMass | kMomentum | kForce>();
      grid_update(NodeV::Momentum);
      g2p<G2pMode::Velocity>();
      update_stress(grid_.v, Positions::Move);
      break;
    case Scheme::MUSL:  // update stress last, from remapped velocities (000, section 2)
      p2g<kMass | kMomentum | kForce>();              // m_i, p_i, f_i (000, eqs. 1-5)
      grid_update(NodeV::Momentum);                   // p_i += f_i dt (000, eq. 6)
      g2p<G2pMode::Remap>();                          // v_p (eqs. 8, 10); remap m_p v_p (eq. 11)
      grid_remap();                                   // v_i = remapped p_i / m_i
      update_stress(grid_.v_remap, Positions::Move);  // x_p (eqs. 7, 9); stress (eqs. 12-15)
      break;
  }
  if constexpr (GridT::kGraded) split_particles();  // coarse particles in finer cells (004, 3.3)
  // USF computes its forces from the stress it just updated, MUSL and USL from last step's.
  const double internal_paired = scheme_ == Scheme::USF ? balance_.internal : internal_start;
  balance_.leapfrog_total =
      leapfrog_kinetic_ + internal_paired + balance_.removed - balance_.external_work;
  this->end_step(dt, "lower solver.cfl");  // the clock, the energy guard
}

// ------------------------------------------------------------------------------------------
// Construction and bookkeeping

template <Grid GridT>
ExplicitSolver<GridT>::ExplicitSolver(const Scene& scene, GridT grid, ColumnStore& particles,
                                      ScatterStrategy strategy)
    : Core(scene, std::move(grid), particles),
      scheme_(scene.solver.scheme),
      scatter_(strategy),
      contact_(scene),
      cfl_(scene.solver.cfl),
      dt_max_(scene.solver.dt_max) {
  if (strategy == ScatterStrategy::LRSlabs) binning_.target_chunks = 2 * omp_get_max_threads();
  if (contact_.active() && strategy != ScatterStrategy::Colored &&
      strategy != ScatterStrategy::LRSlabs)
    throw InputError("--strategy",
                     "a scene with [[contact]] needs the colored (default) or "
                     "lr-slabs strategy: the bodies' fields have no private copies");
  sort_particles();
  stable_dt_ = this->start_energies();  // initial energies and the first stable time step
}

template <Grid GridT>
ExplicitSolver<GridT>::~ExplicitSolver() = default;

template <Grid GridT>
std::size_t ExplicitSolver<GridT>::work_bytes() const {
  std::size_t b = grid_.nodes() * (sizeof(double) + 3 * sizeof(Vec<D>) + (has_rigid_ ? 1 : 0));
  b += scatter_.bytes() + contact_.bytes();
  b += binning_.bins().capacity() * sizeof(Bin) + binning_.chunks().capacity() * sizeof(Chunk);
  return b;
}

/// Reduces the per-chunk results in chunk order (throws on the first fault) into what the
/// kernel changed: velocities (the leapfrog kinetic energy), stresses (internal energy and the
/// stable step), positions (kinetic energy, momentum, work; a re-sort when particles left
/// the window or the domain, or too many left their bins).
template <Grid GridT>
void ExplicitSolver<GridT>::finish(std::vector<ChunkSums>& stats, int changed) {
  ChunkSums total;
  reduce(stats, total);
  if (changed & kVelocities) leapfrog_kinetic_ = total.leapfrog_kinetic;
  if (changed & kStresses) {
    balance_.internal = total.internal;
    stable_dt_ = std::min(dt_max_, cfl_ * total.dt_min);
  }
  if (changed & kPositions) {
    balance_.kinetic = total.kinetic;
    balance_.momentum = total.momentum;
    balance_.external_work += total.work;
    const double n = double(std::max<std::size_t>(1, particles_.size()));
    if (total.out_of_window || !exits_.empty() || total.strays > 0.01 * n ||
        total.off_bin > 0.1 * n)
      need_sort_ = true;
  }
}

}  // namespace mpm
