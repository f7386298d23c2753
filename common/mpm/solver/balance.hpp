#pragma once
/// The energy and momentum balance of a run, the per-chunk sums the particle kernels reduce
/// into it, and the energy that particles leaving the domain take with them. Shared by the
/// explicit and implicit solvers.
#include <algorithm>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "mpm/core/columns.hpp"
#include "mpm/core/types.hpp"
#include "mpm/scene/particles.hpp"
#include "mpm/solver/materials/material.hpp"

namespace mpm {

/// Energies (J; per metre of thickness in plane strain, per radian in axisymmetry) and
/// momentum after a step.
struct Balance {
  double kinetic = 0;            ///< sum of m v^2 / 2 over the deformable particles
  double internal = 0;           ///< sum of m e (elastic, plastic and shock heating)
  double external_work = 0;      ///< work of body forces, loads and rigid bodies since t = 0
  double removed = 0;            ///< kinetic + internal energy of particles removed at the domain
  Vec3 momentum = Vec3::Zero();  ///< kg m/s
  double removed_mass = 0;       ///< kg, of the particles removed at the domain
  Vec3 removed_momentum = Vec3::Zero();  ///< kg m/s, theirs when they left
  /// kinetic + internal + removed - external_work. The kinetic energy is taken at the half
  /// step and the internal energy at the full step, so this swings by O(dt) in impacts.
  double total() const { return kinetic + internal + removed - external_work; }
  /// The energy central differences conserve: sum m v(k-1/2).v(k+1/2) / 2 plus the internal
  /// energy of the configuration the forces came from, at the start of the last step. No O(dt)
  /// swing: the energy guard watches this one. The implicit solver has no half steps: total().
  double leapfrog_total = 0;
};

/// Per-chunk results of a particle kernel, reduced in chunk order (SolverCore::reduce) so
/// that sums do not depend on the thread count.
struct ChunkSums {
  double kinetic = 0, internal = 0;  ///< J: m v^2 / 2, m e
  /// J: work of body forces and loads over the step, F.(v_old + v_new) dt / 2, the change of
  /// kinetic energy they cause; work_start: its part at the velocity before the step.
  double work = 0, work_start = 0;
  double leapfrog_kinetic = 0;                              ///< J: m v(k-1/2).v(k+1/2) / 2
  Vec3 momentum = Vec3::Zero();                             ///< kg m/s
  double dt_min = std::numeric_limits<double>::infinity();  ///< s: min h / (c + |v|), no cfl
  long off_bin = 0;                  ///< particles that left their bin's cell
  long strays = 0;                   ///< ... and its slab layer
  bool out_of_window = false;        ///< a particle left the grid's window (or sparse cells)
  std::vector<std::uint32_t> exits;  ///< particles that left the domain
  long fault = -1;                   ///< particle index of the first fault
  std::string cause;                 ///< of that fault

  /// Kinetic energy and momentum of particle i, just moved.
  template <int D>
  void add_motion(const ParticleView<D>& p, std::uint32_t i) {
    kinetic += 0.5 * p.m[i] * p.v[i].squaredNorm();
    for (int a = 0; a < D; ++a) momentum[a] += p.m[i] * p.v[i][a];
  }
  /// The work of the body force b (m/s^2) and the load on particle i over a step of dt (s)
  /// that took its velocity from v_old to p.v[i]: with the mean of the two, as the kinetic
  /// energy changes (m (v_new^2 - v_old^2) / 2 = F.(v_new + v_old) dt / 2 for a force F).
  template <int D>
  void add_load_work(const ParticleView<D>& p, std::uint32_t i, double dt, const Vec<D>& b,
                     const Vec<D>& v_old) {
    const Vec<D> F = p.m[i] * b + (p.f_ext ? p.f_ext[i] : Vec<D>::Zero());
    const double w_old = 0.5 * dt * F.dot(v_old);
    work += w_old + 0.5 * dt * F.dot(p.v[i]);
    work_start += w_old;
  }
};

/// Particles that left the domain (indices in `exits`, possibly repeated) take their energy
/// with them: it moves from kinetic and internal to `removed`, and their mass and momentum
/// to `removed_mass` and `removed_momentum`. Sorts and de-duplicates
/// `exits` (the sort then drops them) and returns how many there are. Rigid particles carry
/// no energy of the balance.
template <int D>
std::size_t account_exits(ColumnStore& particles, std::vector<std::uint32_t>& exits,
                          Balance& balance) {
  if (exits.empty()) return 0;
  const ParticleView<D> p = view<D>(particles);
  std::sort(exits.begin(), exits.end());
  exits.erase(std::unique(exits.begin(), exits.end()), exits.end());
  for (auto i : exits) {
    if (p.material[i] == kRigidMaterial) continue;
    const double ke = 0.5 * p.m[i] * p.v[i].squaredNorm(), ie = p.m[i] * p.e[i];
    balance.removed += ke + ie;
    balance.kinetic -= ke;
    balance.internal -= ie;
    balance.removed_mass += p.m[i];
    for (int a = 0; a < D; ++a) {
      balance.removed_momentum[a] += p.m[i] * p.v[i][a];
      balance.momentum[a] -= p.m[i] * p.v[i][a];
    }
  }
  return exits.size();
}

/// Adds the deformable particles' kinetic and internal energy and momentum to `balance` and
/// returns the fastest signal, max(reference wave speed + |v|), which sets the first step.
template <int D>
double start_balance(const ParticleView<D>& p, const std::vector<Material>& materials,
                     Balance& balance) {
  double speed = 0;
  for (std::size_t i = 0; i < p.n; ++i) {
    if (p.material[i] == kRigidMaterial) continue;
    balance.kinetic += 0.5 * p.m[i] * p.v[i].squaredNorm();
    balance.internal += p.m[i] * p.e[i];
    for (int a = 0; a < D; ++a) balance.momentum[a] += p.m[i] * p.v[i][a];
    if (p.material[i] == kRebarNode) continue;  // their elements' step: RebarTruss
    speed = std::max(speed, materials[p.material[i]].reference_wave_speed() + p.v[i].norm());
  }
  return speed;
}

}  // namespace mpm
