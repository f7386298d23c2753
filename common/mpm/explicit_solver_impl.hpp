#pragma once
// Explicit MPM. The time step is ExplicitSolver::step, right below: a few named kernels whose
// order is the only difference between USF, USL and MUSL. The kernels follow it. Included by
// the translation units that instantiate the solver for a grid type.
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "mpm/error.hpp"
#include "mpm/explicit_solver.hpp"

namespace mpm {

template <class GridT>
void ExplicitSolver<GridT>::step(double dt) {
  dt_ = dt;
  if (need_sort_) sort_particles();  // cell order; the grid window follows the material
  const double internal_start = balance_.internal;
  switch (scheme_) {
    case Scheme::USF:  // update stress first (004, section 3.4)
      p2g<kMass | kMomentum>();        // m_i, p_i (004, eqs. 24-25)
      grid_velocity();                 // v_i = p_i / m_i, boundary conditions
      update_stress(grid_.v, false);   // strain rate, spin, stress (004, eqs. 26-27)
      p2g<kForce>();                   // f_i (004, eqs. 28-29)
      grid_update(false);              // p_i += f_i dt (004, eq. 30)
      g2p<false, true>();              // v_p, x_p (004, eqs. 9-10)
      break;
    case Scheme::USL:  // update stress last
      p2g<kMass | kMomentum | kForce>();
      grid_update(true);
      g2p<false, false>();
      update_stress(grid_.v, true);
      break;
    case Scheme::MUSL:  // update stress last, from remapped velocities (000, section 2)
      p2g<kMass | kMomentum | kForce>();  // m_i, p_i, f_i (000, eqs. 1-5)
      grid_update(true);                  // p_i += f_i dt (000, eq. 6)
      g2p<true, false>();                 // v_p (eqs. 8, 10); remap m_p v_p (eq. 11)
      grid_remap();                       // v_i = remapped p_i / m_i
      update_stress(grid_.v_remap, true); // x_p (eqs. 7, 9); stress (eqs. 12-15)
      break;
  }
  if constexpr (GridT::kGraded) split_particles();  // coarse particles in finer cells (004, 3.3)
  // USF computes its forces from the stress it just updated, MUSL and USL from last step's.
  const double internal_paired = scheme_ == Scheme::USF ? balance_.internal : internal_start;
  balance_.leapfrog_total =
      leapfrog_kinetic_ + internal_paired + balance_.removed - balance_.external_work;
  time_ += dt;
  ++steps_;
  particle_steps_ += double(particles_.size());
  check_energy();
}

// ------------------------------------------------------------------------------------------
// Construction and bookkeeping

/// Per-chunk results of a particle kernel, reduced in chunk order so that sums do not depend
/// on the thread count.
template <class GridT>
struct ExplicitSolver<GridT>::ChunkStats {
  double kinetic = 0, internal = 0, work = 0, leapfrog_kinetic = 0;
  Vec3 momentum = Vec3::Zero();
  double dt_min = std::numeric_limits<double>::infinity();
  long off_bin = 0, strays = 0;
  bool out_of_window = false;
  std::vector<std::uint32_t> exits;
  long fault = -1;  ///< particle index of the first fault
  std::string cause;
};

/// Per-thread scratch of the stress kernel.
template <class GridT>
struct ExplicitSolver<GridT>::StressScratch {
  Mat3 L[kBlock];
  double c[kBlock];
  BlockScratch S;
};

template <class GridT>
ExplicitSolver<GridT>::ExplicitSolver(const Scene& scene, GridT grid, ColumnStore& particles)
    : scene_(scene),
      particles_(particles),
      grid_(std::move(grid)),
      scheme_(scene.solver.scheme),
      axisymmetric_(D == 2 && scene.axisymmetric),
      cfl_(scene.solver.cfl),
      dt_max_(scene.solver.dt_max) {
  prepare_columns(particles_, scene_);
  for (const auto& m : scene_.materials) materials_.emplace_back(m, scene_.solver);
  for (int a = 0; a < D; ++a) gravity_[a] = scene_.solver.gravity[a];
  rigid_velocity_.assign(scene_.bodies.size(), Vec<D>::Zero());
  rigid_force_.assign(scene_.bodies.size(), Vec3::Zero());
  for (std::size_t b = 0; b < scene_.bodies.size(); ++b)
    if (scene_.bodies[b].rigid) {
      has_rigid_ = true;
      for (int a = 0; a < D; ++a) rigid_velocity_[b][a] = scene_.bodies[b].velocity[a];
    }
  const int threads = omp_get_max_threads();
  strays_.resize(threads);
  scratch_.resize(threads);
  for (auto& s : scratch_) s = std::make_unique<StressScratch>();

  // Every particle must start inside the domain.
  ParticleView<D> p = view<D>(particles_);
  double m_min = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < p.n; ++i) {
    std::int64_t key;
    Vec<D> xi;
    if (!p.x[i].allFinite() || grid_.where(p.x[i], key, xi) == Where::OutsideDomain)
      throw InputError("model", "particle " + std::to_string(p.id[i]) +
                                    " lies outside the domain of the grid");
    if (p.material[i] != kRigidMaterial) m_min = std::min(m_min, p.m[i]);
  }
  node_mass_floor_ = 1e-14 * (std::isfinite(m_min) ? m_min : 1.0);
  sort_particles();

  // Initial energies and the first stable time step.
  p = view<D>(particles_);
  double speed = 0;
  for (std::size_t i = 0; i < p.n; ++i) {
    if (p.material[i] == kRigidMaterial) continue;
    balance_.kinetic += 0.5 * p.m[i] * p.v[i].squaredNorm();
    balance_.internal += p.m[i] * p.e[i];
    for (int a = 0; a < D; ++a) balance_.momentum[a] += p.m[i] * p.v[i][a];
    speed = std::max(speed, materials_[p.material[i]].reference_wave_speed() + p.v[i].norm());
  }
  total0_ = balance_.leapfrog_total = balance_.total();
  energy_scale_ = std::max(std::abs(total0_), balance_.kinetic);
  const double h = grid_.min_cell_size();
  stable_dt_ = std::min(dt_max_, speed > 0 ? cfl_ * h / speed : dt_max_);
}

template <class GridT>
ExplicitSolver<GridT>::~ExplicitSolver() = default;

template <class GridT>
void ExplicitSolver<GridT>::sort_particles() {
  ScopedTimer timer(timers_, timers_.id("sort"));
  if (!exits_.empty()) {
    // Particles that left the domain take their energy with them (balance_.removed).
    const ParticleView<D> p = view<D>(particles_);
    std::sort(exits_.begin(), exits_.end());
    exits_.erase(std::unique(exits_.begin(), exits_.end()), exits_.end());
    for (auto i : exits_) {
      if (p.material[i] == kRigidMaterial) continue;
      const double ke = 0.5 * p.m[i] * p.v[i].squaredNorm(), ie = p.m[i] * p.e[i];
      balance_.removed += ke + ie;
      balance_.kinetic -= ke;
      balance_.internal -= ie;
    }
    removed_count_ += exits_.size();
  }
  binning_.sort(particles_, grid_, exits_);
  exits_.clear();
  need_sort_ = false;
}

template <class GridT>
void ExplicitSolver<GridT>::check_energy() {
  const double total = balance_.leapfrog_total;
  energy_scale_ = std::max({energy_scale_, balance_.kinetic, std::abs(balance_.external_work)});
  const double growth = total - total0_;
  if (growth > scene_.solver.energy_growth_limit * energy_scale_ && energy_scale_ > 0) {
    char msg[256];
    std::snprintf(msg, sizeof msg,
                  "total energy grew by %.3g J, %.1f%% of its scale %.3g J (limit "
                  "solver.energy_growth_limit = %g): lower solver.cfl",
                  growth, 100.0 * growth / energy_scale_, energy_scale_,
                  scene_.solver.energy_growth_limit);
    throw InstabilityError(steps_, time_, -1, msg);
  }
}

/// Reduces the per-chunk results in chunk order; throws on the first fault.
template <class GridT>
void ExplicitSolver<GridT>::finish(std::vector<ChunkStats>& stats, bool moved, bool stressed,
                                   bool velocity) {
  const ParticleView<D> p = view<D>(particles_);
  double internal = 0, dt_min = std::numeric_limits<double>::infinity();
  double kinetic = 0, work = 0, leapfrog_kinetic = 0;
  Vec3 momentum = Vec3::Zero();
  long off_bin = 0, strays = 0;
  bool out_of_window = false;
  for (auto& s : stats) {
    if (s.fault >= 0) throw InstabilityError(steps_ + 1, time_ + dt_, p.id[s.fault], s.cause);
    internal += s.internal;
    dt_min = std::min(dt_min, s.dt_min);
    kinetic += s.kinetic;
    leapfrog_kinetic += s.leapfrog_kinetic;
    work += s.work;
    momentum += s.momentum;
    off_bin += s.off_bin;
    strays += s.strays;
    out_of_window = out_of_window || s.out_of_window;
    for (auto i : s.exits) {
      if (scene_.solver.on_exit == OnExit::Stop) {
        char where[160];
        std::snprintf(where, sizeof where, "left the domain at (%.4g, %.4g, %.4g) m",
                      p.x[i][0], p.x[i][1], D == 3 ? p.x[i][D - 1] : 0.0);
        throw InstabilityError(steps_ + 1, time_ + dt_, p.id[i],
                               std::string(where) +
                                   " (enlarge grid.domain, or set solver.on_exit = \"remove\")");
      }
      exits_.push_back(i);
    }
  }
  if (velocity) leapfrog_kinetic_ = leapfrog_kinetic;
  if (stressed) {
    balance_.internal = internal;
    stable_dt_ = std::min(dt_max_, cfl_ * dt_min);
  }
  if (moved) {
    balance_.kinetic = kinetic;
    balance_.momentum = momentum;
    balance_.external_work += work;
    // Re-sort when particles left the window or the domain, or too many left their bins.
    const double n = double(std::max<std::size_t>(1, p.n));
    if (out_of_window || !exits_.empty() || strays > 0.01 * n || off_bin > 0.1 * n)
      need_sort_ = true;
  }
}

template <class GridT>
void ExplicitSolver<GridT>::track_move(const Vec<D>& x, std::uint32_t i, std::int64_t bin_key,
                                       ChunkStats& s) const {
  if (!x.allFinite()) {
    if (s.fault < 0) s.fault = i, s.cause = "its position is not finite";
    return;
  }
  std::int64_t key = -1;
  Vec<D> xi;
  switch (grid_.where(x, key, xi)) {
    case Where::OutsideDomain: s.exits.push_back(i); break;
    case Where::OutsideWindow: s.out_of_window = true; break;
    case Where::Window:
      if (key != bin_key) {
        ++s.off_bin;
        if (grid_.layer(key) != grid_.layer(bin_key)) ++s.strays;
      }
      break;
  }
}

// ------------------------------------------------------------------------------------------
// Particle to grid (000, eqs. 1-5): lumped mass, momentum, internal force, body forces and
// loads; rigid particles mark the nodes they touch instead. Chunks of one colour run in
// parallel; a particle in its bin's cell adds into registers flushed once per cell, one
// outside its bin's layer (a stray) is done serially at the end.

template <class GridT>
template <int F>
void ExplicitSolver<GridT>::p2g() {
  ScopedTimer timer(timers_, timers_.id(F == kForce ? "p2g_force"
                                        : (F & kForce) ? "p2g"
                                                       : "p2g_mass_momentum"));
  constexpr bool kM = F & kMass, kP = F & kMomentum, kF = F & kForce;
  if constexpr (kM) grid_.clear(scheme_ == Scheme::MUSL, has_rigid_);
  const ParticleView<D> p = view<D>(particles_);
  material_ = p.material;
  double* m_i = grid_.m.data();
  Vec<D>* p_i = grid_.v.data();
  Vec<D>* f_i = grid_.a.data();
  std::uint8_t* rigid_i = has_rigid_ ? grid_.rigid.data() : nullptr;
  const auto& bins = binning_.bins();
  const auto& chunks = binning_.chunks();
  const int nchunks = binning_.chunk_count();
  const Vec<D> b = gravity_;
  const bool axi = axisymmetric_;

  // Contribution of particle i (cell `key`, local coordinates xi) through add(c, dm, dp, df).
  auto contribute = [&](std::uint32_t i, std::int64_t key, const Vec<D>& xi, auto&& add) {
    double N[NMAX];
    Vec<D> G[NMAX];
    if constexpr (kF) grid_.shape(key, xi, N, G);
    else grid_.values(key, xi, N);
    std::int64_t cell[NMAX];
    const int nn = GridT::kFixedNodes ? NMAX : grid_.cell_nodes(key, cell);
    if (rigid(i)) {  // rigid bodies impose their velocity on the nodes they touch
      if constexpr (kM) {
        if (rigid_i) {
          grid_.cell_nodes(key, cell);
          for (int c = 0; c < nn; ++c)
            if (N[c] > 0) rigid_i[cell[c]] = std::uint8_t(p.body[i] + 1);
        }
      }
      return;
    }
    const double m_p = p.m[i];
    const Vec<D> mv_p = m_p * p.v[i];
    Mat<D> Vsigma = Mat<D>::Zero();  // V_p sigma_p, in-plane part
    double Vs_hoop_r = 0;            // axisymmetric: V_p sigma_thetatheta / r_p
    Vec<D> fb = m_p * b;             // body force and load
    if constexpr (kF) {
      const double V = m_p / p.rho[i];
      Vsigma = V * to_matrix(p.sigma[i]).template topLeftCorner<D, D>();
      if (axi) Vs_hoop_r = V * p.sigma[i][2] / p.x[i][0];
      if (p.f_ext) fb += p.f_ext[i];
    }
    for (int c = 0; c < nn; ++c) {
      Vec<D> df = Vec<D>::Zero();
      if constexpr (kF) {
        df = N[c] * fb - Vsigma * G[c];  // (000, eqs. 4-5)
        if (axi) df[0] -= Vs_hoop_r * N[c];  // hoop stress (Sulsky & Schreyer 1996)
      }
      add(c, m_p * N[c], N[c] * mv_p, df);
    }
  };
  auto to_grid = [&](std::int64_t key) {
    std::array<std::int64_t, NMAX> nodes;
    grid_.cell_nodes(key, nodes.data());
    return [&, nodes](int c, double dm, const Vec<D>& dp, const Vec<D>& df) {
      const std::int64_t n = nodes[c];
      if constexpr (kM) m_i[n] += dm;
      if constexpr (kP) p_i[n] += dp;
      if constexpr (kF) f_i[n] += df;
    };
  };

#pragma omp parallel
  {
    auto& strays = strays_[omp_get_thread_num()];
    strays.clear();
    for (int color = 0; color < 2; ++color) {
#pragma omp for schedule(dynamic, 1)
      for (int ch = color; ch < nchunks; ch += 2) {
        for (std::uint32_t bi = chunks[ch].bin_begin; bi < chunks[ch].bin_end; ++bi) {
          const Bin& bin = bins[bi];
          const int layer = grid_.layer(bin.key);
          std::int64_t nodes[NMAX];
          const int nn = grid_.cell_nodes(bin.key, nodes);
          double m_c[NMAX] = {};
          Vec<D> p_c[NMAX], f_c[NMAX];
          for (int c = 0; c < nn; ++c) p_c[c].setZero(), f_c[c].setZero();
          auto to_cell = [&](int c, double dm, const Vec<D>& dp, const Vec<D>& df) {
            if constexpr (kM) m_c[c] += dm;
            if constexpr (kP) p_c[c] += dp;
            if constexpr (kF) f_c[c] += df;
          };
          for (std::uint32_t i = bin.begin; i < bin.end; ++i) {
            std::int64_t key;
            Vec<D> xi;
            grid_.locate(p.x[i], key, xi);
            if (key == bin.key) contribute(i, key, xi, to_cell);
            else if (grid_.layer(key) == layer) contribute(i, key, xi, to_grid(key));
            else strays.push_back(i);
          }
          for (int c = 0; c < nn; ++c) {
            const std::int64_t n = nodes[c];
            if constexpr (kM) m_i[n] += m_c[c];
            if constexpr (kP) p_i[n] += p_c[c];
            if constexpr (kF) f_i[n] += f_c[c];
          }
        }
      }
    }
  }
  // Strays, serially and in particle order.
  std::vector<std::uint32_t> all;
  for (auto& s : strays_) all.insert(all.end(), s.begin(), s.end());
  std::sort(all.begin(), all.end());
  for (auto i : all) {
    std::int64_t key;
    Vec<D> xi;
    grid_.locate(p.x[i], key, xi);
    contribute(i, key, xi, to_grid(key));
  }
}

// ------------------------------------------------------------------------------------------
// Grid kernels: nodal velocities and accelerations, boundary conditions (000, eq. 6), rigid
// bodies (no-slip: the nodes they touch take their velocity; the force that takes is the
// force between material and body).

template <class GridT>
void ExplicitSolver<GridT>::apply_boundary(std::vector<Vec<D>>& vel, std::vector<Vec<D>>* acc,
                                           bool record_force) {
  // Record the force each face carries (before holding the velocities), then hold them.
  if (record_force) {
    face_force_.fill(0.0);
    auto record = [&](std::int64_t n, int face) {
      const int axis = face / 2;
      const double sign = (face % 2 == 0) ? -1.0 : 1.0;
      face_force_[face] += sign * grid_.m[n] * vel[n][axis] / dt_;
    };
    for (const auto& f : grid_.fixed_nodes()) record(f.node, f.face);
    for (const auto& f : grid_.slip_nodes()) record(f.node, f.face);
  }
  for (const auto& f : grid_.fixed_nodes()) {
    vel[f.node].setZero();
    if (acc) (*acc)[f.node].setZero();
  }
  for (const auto& f : grid_.slip_nodes()) {
    vel[f.node][f.face / 2] = 0.0;
    if (acc) (*acc)[f.node][f.face / 2] = 0.0;
  }
  if (!has_rigid_) return;
  // Rigid bodies, serially (a few nodes; the force sums stay in node order).
  if (record_force)
    for (auto& f : rigid_force_) f.setZero();
  const std::int64_t n = std::int64_t(grid_.nodes());
  for (std::int64_t i = 0; i < n; ++i) {
    const int mark = grid_.rigid[i];
    if (mark == 0 || grid_.m[i] <= node_mass_floor_) continue;
    const Vec<D>& vb = rigid_velocity_[mark - 1];
    if (record_force) {
      const Vec<D> F = grid_.m[i] * (vel[i] - vb) / dt_;  // what the body must push back
      for (int a = 0; a < D; ++a) rigid_force_[mark - 1][a] += F[a];
      balance_.external_work -= dt_ * F.dot(vb);  // work of the body on the material
    }
    if (acc) (*acc)[i] += (vb - vel[i]) / dt_;
    vel[i] = vb;
  }
}

template <class GridT>
void ExplicitSolver<GridT>::grid_velocity() {
  ScopedTimer timer(timers_, timers_.id("grid_velocity"));
  const std::int64_t n = std::int64_t(grid_.nodes());
  const double floor = node_mass_floor_;
#pragma omp parallel for schedule(static)
  for (std::int64_t i = 0; i < n; ++i) {
    if (grid_.m[i] > floor) grid_.v[i] /= grid_.m[i];
    else grid_.v[i].setZero();
  }
  apply_boundary(grid_.v, nullptr, false);
}

template <class GridT>
void ExplicitSolver<GridT>::grid_update(bool momentum_in_v) {
  ScopedTimer timer(timers_, timers_.id("grid_update"));
  const std::int64_t n = std::int64_t(grid_.nodes());
  const double floor = node_mass_floor_, dt = dt_;
#pragma omp parallel for schedule(static)
  for (std::int64_t i = 0; i < n; ++i) {
    const double m = grid_.m[i];
    if (m > floor) {
      const Vec<D> a_i = grid_.a[i] / m;
      const Vec<D> v_i = momentum_in_v ? Vec<D>(grid_.v[i] / m) : grid_.v[i];
      grid_.v[i] = v_i + dt * a_i;  // p_i^{k+1} = p_i^k + f_i dt, divided by m_i
      grid_.a[i] = a_i;
    } else {
      grid_.v[i].setZero();
      grid_.a[i].setZero();
    }
  }
  apply_boundary(grid_.v, &grid_.a, true);
}

template <class GridT>
void ExplicitSolver<GridT>::grid_remap() {
  ScopedTimer timer(timers_, timers_.id("grid_remap"));
  const std::int64_t n = std::int64_t(grid_.nodes());
  const double floor = node_mass_floor_;
#pragma omp parallel for schedule(static)
  for (std::int64_t i = 0; i < n; ++i) {
    if (grid_.m[i] > floor) grid_.v_remap[i] /= grid_.m[i];
    else grid_.v_remap[i].setZero();
  }
  apply_boundary(grid_.v_remap, nullptr, false);
}

// ------------------------------------------------------------------------------------------
// Grid to particle: velocity (000, eqs. 8, 10), position when Move (eqs. 7, 9), and for MUSL
// the remapped momentum m_p v_p back to the grid (eq. 11), a scatter done by colours. Rigid
// particles keep their velocity and, when Move, advance with it.

template <class GridT>
template <bool Remap, bool Move>
void ExplicitSolver<GridT>::g2p() {
  ScopedTimer timer(timers_, timers_.id(Remap ? "g2p_remap" : Move ? "g2p_move" : "g2p"));
  const ParticleView<D> p = view<D>(particles_);
  material_ = p.material;
  const Vec<D>* a_i = grid_.a.data();
  const Vec<D>* v_i = grid_.v.data();
  Vec<D>* q_i = grid_.v_remap.data();
  const auto& bins = binning_.bins();
  const auto& chunks = binning_.chunks();
  const int nchunks = binning_.chunk_count();
  const double dt = dt_;
  const Vec<D> b = gravity_;
  std::vector<ChunkStats> stats(nchunks);

  auto chunk_body = [&](int ch, std::vector<std::uint32_t>& strays) {
    ChunkStats& s = stats[ch];
    for (std::uint32_t bi = chunks[ch].bin_begin; bi < chunks[ch].bin_end; ++bi) {
      const Bin& bin = bins[bi];
      const int layer = grid_.layer(bin.key);
      std::int64_t nodes[NMAX], other[NMAX];
      const int nn = grid_.cell_nodes(bin.key, nodes);
      Vec<D> a_c[NMAX], v_c[NMAX], q_c[NMAX];
      for (int c = 0; c < nn; ++c) {
        a_c[c] = a_i[nodes[c]];
        if constexpr (Move) v_c[c] = v_i[nodes[c]];
        q_c[c].setZero();
      }
      for (std::uint32_t i = bin.begin; i < bin.end; ++i) {
        if (rigid(i)) {
          if constexpr (Move) {
            p.x[i] += dt * p.v[i];
            track_move(p.x[i], i, bin.key, s);
          }
          continue;
        }
        std::int64_t key;
        Vec<D> xi;
        grid_.locate(p.x[i], key, xi);
        const bool home = key == bin.key;
        const int nk = home ? nn : grid_.cell_nodes(key, other);
        const std::int64_t* nd = home ? nodes : other;
        double N[NMAX];
        grid_.values(key, xi, N);
        Vec<D> a_p = Vec<D>::Zero(), vbar = Vec<D>::Zero();
        for (int c = 0; c < nk; ++c) {
          a_p += N[c] * (home ? a_c[c] : a_i[nd[c]]);
          if constexpr (Move) vbar += N[c] * (home ? v_c[c] : v_i[nd[c]]);
        }
        const Vec<D> v_old = p.v[i];
        p.v[i] += dt * a_p;  // (000, eq. 8)
        s.leapfrog_kinetic += 0.5 * p.m[i] * v_old.dot(p.v[i]);
        if constexpr (Move) {
          p.x[i] += dt * vbar;  // (000, eq. 7)
          s.kinetic += 0.5 * p.m[i] * p.v[i].squaredNorm();
          for (int a = 0; a < D; ++a) s.momentum[a] += p.m[i] * p.v[i][a];
          s.work += dt * (p.m[i] * b + (p.f_ext ? p.f_ext[i] : Vec<D>::Zero())).dot(p.v[i]);
          track_move(p.x[i], i, bin.key, s);
        }
        if constexpr (Remap) {
          const Vec<D> mv = p.m[i] * p.v[i];
          if (home) {
            for (int c = 0; c < nk; ++c) q_c[c] += N[c] * mv;
          } else if (grid_.layer(key) == layer) {
            for (int c = 0; c < nk; ++c) q_i[nd[c]] += N[c] * mv;
          } else {
            strays.push_back(i);
          }
        }
      }
      if constexpr (Remap)
        for (int c = 0; c < nn; ++c) q_i[nodes[c]] += q_c[c];
    }
  };

#pragma omp parallel
  {
    auto& strays = strays_[omp_get_thread_num()];
    strays.clear();
    if constexpr (Remap) {
      for (int color = 0; color < 2; ++color) {
#pragma omp for schedule(dynamic, 1)
        for (int ch = color; ch < nchunks; ch += 2) chunk_body(ch, strays);
      }
    } else {
#pragma omp for schedule(dynamic, 1)
      for (int ch = 0; ch < nchunks; ++ch) chunk_body(ch, strays);
    }
  }
  if constexpr (Remap) {
    std::vector<std::uint32_t> all;
    for (auto& s : strays_) all.insert(all.end(), s.begin(), s.end());
    std::sort(all.begin(), all.end());
    for (auto i : all) {
      std::int64_t key;
      Vec<D> xi;
      grid_.locate(p.x[i], key, xi);
      double N[NMAX];
      std::int64_t nd[NMAX];
      grid_.values(key, xi, N);
      const int nk = grid_.cell_nodes(key, nd);
      for (int c = 0; c < nk; ++c) q_i[nd[c]] += N[c] * (p.m[i] * p.v[i]);
    }
  }
  finish(stats, Move, false, true);
}

// ------------------------------------------------------------------------------------------
// Stress update (000, eqs. 12-15): velocity gradient from the grid (in axisymmetry with the
// hoop rate v_r / r), then the material update once per block of particles of one material.
// When `move`, positions advance with the grid velocity (000, eqs. 7, 9) in the same pass.

template <class GridT>
void ExplicitSolver<GridT>::update_stress(const std::vector<Vec<D>>& v_grad, bool move) {
  ScopedTimer timer(timers_, timers_.id(move ? "stress_move" : "stress"));
  ParticleView<D> p = view<D>(particles_);
  material_ = p.material;
  const Vec<D>* vg_i = v_grad.data();
  const Vec<D>* v_i = grid_.v.data();
  const auto& bins = binning_.bins();
  const auto& chunks = binning_.chunks();
  const int nchunks = binning_.chunk_count();
  const double dt = dt_;
  const Vec<D> b = gravity_;
  const bool axi = axisymmetric_;
  std::vector<ChunkStats> stats(nchunks);

#pragma omp parallel
  {
    StressScratch& scr = *scratch_[omp_get_thread_num()];
#pragma omp for schedule(dynamic, 1)
    for (int ch = 0; ch < nchunks; ++ch) {
      ChunkStats& s = stats[ch];
      std::uint32_t i0 = 0;
      int k = 0, mat = -1;
      double h_block = 0;
      // Constitutive update of the pending block [i0, i0 + k) of material `mat`.
      auto flush = [&]() {
        if (k == 0) return;
        MaterialBlock blk;
        blk.n = k;
        blk.dt = dt;
        blk.h = h_block;
        blk.L = scr.L;
        blk.m = p.m + i0;
        blk.sigma = p.sigma + i0;
        blk.rho = p.rho + i0;
        blk.e = p.e + i0;
        blk.eps_p = p.eps_p ? p.eps_p + i0 : nullptr;
        blk.T = p.T ? p.T + i0 : nullptr;
        blk.failed = p.failed ? p.failed + i0 : nullptr;
        blk.c = scr.c;
        materials_[mat].update(blk, scr.S);
        for (int j = 0; j < k; ++j) {
          const std::uint32_t i = i0 + j;
          s.internal += p.m[i] * p.e[i];
          s.dt_min = std::min(s.dt_min, h_block / (scr.c[j] + p.v[i].norm()));
        }
        if (blk.fault_index >= 0 && s.fault < 0) {
          s.fault = i0 + blk.fault_index;
          s.cause = blk.fault == PointFault::VolumeInverted
                        ? "its volume became non-positive (1 + tr(D) dt <= 0)"
                        : "its stress or energy is not finite";
        }
        k = 0;
      };
      for (std::uint32_t bi = chunks[ch].bin_begin; bi < chunks[ch].bin_end; ++bi) {
        const Bin& bin = bins[bi];
        std::int64_t nodes[NMAX], other[NMAX];
        const int nn = grid_.cell_nodes(bin.key, nodes);
        Vec<D> vg_c[NMAX], v_c[NMAX];
        for (int c = 0; c < nn; ++c) {
          vg_c[c] = vg_i[nodes[c]];
          if (move) v_c[c] = v_i[nodes[c]];
        }
        const double h_cell = grid_.cell_size(bin.key);
        for (std::uint32_t i = bin.begin; i < bin.end; ++i) {
          if (rigid(i)) {  // no stress; advances with its own velocity
            if (move) {
              p.x[i] += dt * p.v[i];
              track_move(p.x[i], i, bin.key, s);
            }
            continue;
          }
          std::int64_t key;
          Vec<D> xi;
          grid_.locate(p.x[i], key, xi);
          const bool home = key == bin.key;
          const int nk = home ? nn : grid_.cell_nodes(key, other);
          const std::int64_t* nd = home ? nodes : other;
          double N[NMAX];
          Vec<D> G[NMAX];
          grid_.shape(key, xi, N, G);
          // Velocity gradient L = sum_i v_i (x) G_ip (000, eqs. 12-13 use its parts).
          Mat<D> L = Mat<D>::Zero();
          Vec<D> vbar = Vec<D>::Zero();
          double v_r = 0;
          for (int c = 0; c < nk; ++c) {
            const Vec<D>& vg = home ? vg_c[c] : vg_i[nd[c]];
            L.noalias() += vg * G[c].transpose();
            if (axi) v_r += N[c] * vg[0];
            if (move) vbar += N[c] * (home ? v_c[c] : v_i[nd[c]]);
          }
          if (p.strain) p.strain[i] += dt * L.diagonal();  // for splitting (004, eq. 23)
          if (int(p.material[i]) != mat || k == kBlock || h_cell != h_block) {
            flush();
            mat = p.material[i];
            i0 = i;
            h_block = h_cell;
          }
          scr.L[k].setZero();
          scr.L[k].template topLeftCorner<D, D>() = L;
          if (axi) scr.L[k](2, 2) = v_r / p.x[i][0];  // hoop rate
          ++k;
          if (move) {
            p.x[i] += dt * vbar;  // (000, eq. 7)
            s.kinetic += 0.5 * p.m[i] * p.v[i].squaredNorm();
            for (int a = 0; a < D; ++a) s.momentum[a] += p.m[i] * p.v[i][a];
            s.work += dt * (p.m[i] * b + (p.f_ext ? p.f_ext[i] : Vec<D>::Zero())).dot(p.v[i]);
            track_move(p.x[i], i, bin.key, s);
          }
        }
      }
      flush();
    }
  }
  finish(stats, move, true, false);
}

}  // namespace mpm
