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
#include <cstdio>
#include <optional>
#include <stdexcept>
#include <string>

#include "mpm/solver/explicit/contact.hpp"
#include "mpm/solver/explicit/explicit_solver.hpp"
#include "mpm/solver/explicit/g2p.hpp"
#include "mpm/solver/explicit/graded_split.hpp"
#include "mpm/solver/explicit/grid_update.hpp"
#include "mpm/solver/explicit/p2g.hpp"
#include "mpm/solver/explicit/rebar_forces.hpp"
#include "mpm/solver/explicit/stress.hpp"

namespace mpm {

template <Grid GridT>
void ExplicitSolver<GridT>::step(double dt, double dt_pace) {
  dt_ = dt;
  if (need_sort_) sort_particles();     // cell order; the grid window follows the material
  if (rebar_.active()) rebar_forces();  // truss elements: forces on their nodes (004, 3.4 step 4)
  const double internal_start = balance_.internal, kinetic_start = balance_.kinetic;
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
    case Scheme::APIC:  // affine particle-in-cell (Jiang et al. 2015), stress last as USL
      p2g<kMass | kMomentum | kForce>();        // p_i = sum N m_p (v_p + C_p (x_i - x_p))
      grid_update(NodeV::Momentum);             // v_i = (p_i + f_i dt) / m_i
      g2p<G2pMode::Pic>();                      // v_p = sum N v_i
      update_stress(grid_.v, Positions::Move);  // C_p = B_p D_p^-1; stress; x_p
      break;
  }
  if constexpr (GridT::kGraded) split_particles();  // coarse particles in finer cells (004, 3.3)
  leapfrog_balance(dt, dt_pace, internal_start, kinetic_start);
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
  loads_ = particles_.has(col::f_ext) || !gravity_.isZero();
  if (contact_.active() && strategy != ScatterStrategy::Colored &&
      strategy != ScatterStrategy::LRSlabs)
    throw InputError("--strategy",
                     "a scene with [[contact]] needs the colored (default) or "
                     "lr-slabs strategy: the bodies' fields have no private copies");
  averaged_by_mat_.assign(materials_.size(), 0);
  for (std::size_t k = 0; k < materials_.size(); ++k)
    if (materials_[k].spec().strength.model == StrengthModel::Hjc &&
        materials_[k].spec().hjc.damage_length > 0)
      averaged_.push_back(int(k)), averaged_by_mat_[k] = 1;
  sort_particles();
  stable_dt_ = this->start_energies();  // initial energies and the first stable time step
}

template <Grid GridT>
ExplicitSolver<GridT>::~ExplicitSolver() = default;

/// The energy central differences conserve after a step of dt, paired with the configuration
/// the forces came from: sum m v_old.(v_old + a dt_pace) / 2 = K + r (L - K), r = dt_pace /
/// dt, with K the kinetic energy at the start and L the leapfrog kinetic energy of the step.
/// It is the leapfrog's modified energy for a step of dt_pace, which a step of dt keeps to
/// O(dt^2): a step shortened to land on a frame time no longer moves it by (dt - dt_pace)
/// sum m v.a / 2. The work of the loads is paired the same way: the work before the step
/// and r times its part at the start velocities (the leapfrog total of a particle under a
/// constant force F is then constant to round-off). Rigid bodies' work is booked whole.
template <Grid GridT>
void ExplicitSolver<GridT>::leapfrog_balance(double dt, double dt_pace, double internal_start,
                                             double kinetic_start) {
  // USF computes its forces from the stress it just updated, MUSL and USL from last step's.
  const double internal_paired = scheme_ == Scheme::USF ? balance_.internal : internal_start;
  double kinetic = leapfrog_kinetic_, work = balance_.external_work;
  if (loads_) work += load_work_start_ - load_work_;
  if (dt_pace > 0 && dt_pace != dt) {
    const double r = dt_pace / dt;
    kinetic = kinetic_start + r * (leapfrog_kinetic_ - kinetic_start);
    if (loads_) work += (r - 1) * load_work_start_;
  }
  balance_.leapfrog_total = kinetic + internal_paired + balance_.removed - work;
}

template <Grid GridT>
void ExplicitSolver<GridT>::save_state(StateValues& s) const {
  Core::save_state(s);
  s.set("stable_dt", stable_dt_);
  s.set("leapfrog_kinetic", leapfrog_kinetic_);
  s.set("next_id", double(next_id_));
  s.set("splits", double(split_count_));
  s.set("split_wait", double(split_wait_));
  if (rebar_.active()) s.set("rebar_energy", rebar_sums_.energy);  // in the balance's internal
  if constexpr (GridT::kGraded) grid_.save_state(s);  // restored before the solver is built
}

template <Grid GridT>
void ExplicitSolver<GridT>::restore_state(const StateValues& s) {
  Core::restore_state(s);
  stable_dt_ = s.get("stable_dt");
  leapfrog_kinetic_ = s.get("leapfrog_kinetic");
  next_id_ = std::uint32_t(s.get("next_id"));
  split_count_ = long(s.get("splits"));
  split_wait_ = int(s.get("split_wait"));
  if (rebar_.active()) rebar_sums_.energy = s.get("rebar_energy");
}

template <Grid GridT>
std::size_t ExplicitSolver<GridT>::work_bytes() const {
  std::size_t b = grid_.nodes() * (sizeof(double) + 3 * sizeof(Vec<D>) + (has_rigid_ ? 1 : 0));
  b += scatter_.bytes() + contact_.bytes() + rebar_.bytes();
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
  bool exits = false;  // particles left the domain since the last sort (on any rank)
  if (!ranks_) {
    reduce(stats, total);
    exits = !exits_.empty();
  } else {
    std::optional<InstabilityError> fault;
    try {
      reduce(stats, total);
    } catch (const InstabilityError& e) {
      fault.emplace(e);
    }
    exits = reduce_ranks(total, fault ? &*fault : nullptr);
  }
  if (changed & kVelocities) {
    leapfrog_kinetic_ = total.leapfrog_kinetic;
    load_work_ = total.work;
    load_work_start_ = total.work_start;
    balance_.external_work += total.work;
  }
  if (changed & kStresses) {
    balance_.internal = total.internal;
    double dt_min = total.dt_min;
    if (rebar_.active())  // the truss elements' energy and step (rebar_forces.hpp)
      balance_.internal += rebar_sums_.energy, dt_min = std::min(dt_min, rebar_sums_.dt_min);
    stable_dt_ = std::min(dt_max_, cfl_ * dt_min);
  }
  if (changed & kPositions) {
    balance_.kinetic = total.kinetic;
    balance_.momentum = total.momentum;
    const double n = double(std::max<std::size_t>(1, this->particle_count()));
    if (total.out_of_window || exits || total.strays > 0.01 * n || total.off_bin > 0.1 * n)
      need_sort_ = true;
  }
}

template <Grid GridT>
bool ExplicitSolver<GridT>::reduce_ranks(ChunkSums& t, const InstabilityError* fault) {
  const Comm& comm = Comm::world();
  double v[13] = {t.internal,
                  t.kinetic,
                  t.leapfrog_kinetic,
                  t.work,
                  t.work_start,
                  t.momentum[0],
                  t.momentum[1],
                  t.momentum[2],
                  double(t.off_bin),
                  double(t.strays),
                  t.out_of_window ? 1.0 : 0.0,
                  double(exits_.size()),
                  fault ? 1.0 : 0.0};
  comm.sum(v, 13);
  if (v[12] > 0) throw_rank_fault(fault);
  t.internal = v[0], t.kinetic = v[1], t.leapfrog_kinetic = v[2], t.work = v[3];
  t.work_start = v[4];
  for (int a = 0; a < 3; ++a) t.momentum[a] = v[5 + a];
  t.off_bin = long(v[8]), t.strays = long(v[9]), t.out_of_window = v[10] > 0;
  t.dt_min = comm.min(t.dt_min);
  return v[11] > 0;
}

/// A fault on some rank: every rank throws the lowest faulty rank's InstabilityError.
template <Grid GridT>
void ExplicitSolver<GridT>::throw_rank_fault(const InstabilityError* fault) {
  auto exact = [](double x) {
    char b[32];
    std::snprintf(b, sizeof b, "%.17g", x);
    return std::string(b);
  };
  std::string mine;
  if (fault)
    mine = std::to_string(fault->step) + '\n' + exact(fault->time) + '\n' +
           std::to_string(fault->particle) + '\n' + (fault->left_domain ? "1" : "0") + '\n' +
           fault->cause;
  for (const std::string& text : Comm::world().all_gather(mine)) {
    if (text.empty()) continue;
    Fields f(text);
    const long step = std::stol(f.next());
    const double time = std::stod(f.next());
    const long particle = std::stol(f.next());
    const bool left = f.next() == "1";
    throw InstabilityError(step, time, particle, f.rest(), left);
  }
  throw std::logic_error("a rank reported a fault without its message");
}

}  // namespace mpm
