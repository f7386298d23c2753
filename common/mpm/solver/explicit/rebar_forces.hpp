#pragma once
// Rebar (004, section 3.4, step 4): the truss elements' strains from their nodes' positions,
// their stresses and the forces on their node particles, which p2g scatters to the grid with
// the particles' other forces (004, eq. 13). The elements are in rebar.hpp.
#include "mpm/solver/explicit/explicit_solver.hpp"

namespace mpm {

template <Grid GridT>
void ExplicitSolver<GridT>::rebar_forces() {
  ScopedTimer timer(timers_, timers_.id("rebar"));
  const ParticleView<D> p = view<D>(particles_);
  if (rebar_linked_ != this->sorts_) {  // the particles were reordered: find the nodes again
    rebar_.relink(p);
    rebar_linked_ = this->sorts_;
  }
  const double stored = rebar_sums_.energy;
  rebar_sums_ = rebar_.update(p);
  balance_.internal += rebar_sums_.energy - stored;  // the elements' energy at x^k
}

template <Grid GridT>
void ExplicitSolver<GridT>::attach_rebar(ColumnStore& elements) {
  rebar_.attach(elements, scene_);
  const ParticleView<D> p = view<D>(particles_);
  if (!p.f_rebar) throw InputError("model", "a model with rebar needs the f_rebar column");
  rebar_.relink(p);
  rebar_linked_ = this->sorts_;
  stable_dt_ = std::min(stable_dt_, cfl_ * rebar_.stable_step(p));
}

}  // namespace mpm
