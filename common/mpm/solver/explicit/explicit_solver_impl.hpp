#pragma once
// Explicit MPM. The time step is ExplicitSolver::step, right below: a few named kernels whose
// order is the only difference between USF, USL and MUSL. The kernels follow it. Included by
// the translation units that instantiate the solver for a grid type.
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "mpm/core/error.hpp"
#include "mpm/solver/explicit/explicit_solver.hpp"

namespace mpm {

template <class GridT>
void ExplicitSolver<GridT>::step(double dt) {
  dt_ = dt;
  if (need_sort_) sort_particles();  // cell order; the grid window follows the material
  const double internal_start = balance_.internal;
  switch (scheme_) {
    case Scheme::USF:                 // update stress first (004, section 3.4)
      p2g<kMass | kMomentum>();       // m_i, p_i (004, eqs. 24-25)
      grid_velocity();                // v_i = p_i / m_i, boundary conditions
      update_stress(grid_.v, false);  // strain rate, spin, stress (004, eqs. 26-27)
      p2g<kForce>();                  // f_i (004, eqs. 28-29)
      grid_update(false);             // p_i += f_i dt (004, eq. 30)
      g2p<false, true>();             // v_p, x_p (004, eqs. 9-10)
      break;
    case Scheme::USL:  // update stress last
      p2g<kMass | kMomentum | kForce>();
      grid_update(true);
      g2p<false, false>();
      update_stress(grid_.v, true);
      break;
    case Scheme::MUSL:  // update stress last, from remapped velocities (000, section 2)
      p2g<kMass | kMomentum | kForce>();   // m_i, p_i, f_i (000, eqs. 1-5)
      grid_update(true);                   // p_i += f_i dt (000, eq. 6)
      g2p<true, false>();                  // v_p (eqs. 8, 10); remap m_p v_p (eq. 11)
      grid_remap();                        // v_i = remapped p_i / m_i
      update_stress(grid_.v_remap, true);  // x_p (eqs. 7, 9); stress (eqs. 12-15)
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
ExplicitSolver<GridT>::ExplicitSolver(const Scene& scene, GridT grid, ColumnStore& particles,
                                      ScatterStrategy strategy)
    : scene_(scene),
      particles_(particles),
      grid_(std::move(grid)),
      scheme_(scene.solver.scheme),
      strategy_(strategy),
      axisymmetric_(D == 2 && scene.axisymmetric),
      plane_stress_(D == 2 && scene.plane_stress),
      cfl_(scene.solver.cfl),
      dt_max_(scene.solver.dt_max) {
  prepare_columns(particles_, scene_);
  for (const auto& m : scene_.materials) materials_.emplace_back(m, scene_.solver);
  for (int a = 0; a < D; ++a) gravity_[a] = scene_.solver.gravity[a];
  has_rigid_ = rigid_body_velocities<D>(scene_, rigid_velocity_);
  rigid_held_ = rigid_body_held<D>(scene_);
  rigid_force_.assign(scene_.bodies.size(), Vec3::Zero());
  const int threads = omp_get_max_threads();
  if (strategy_ == ScatterStrategy::LRSlabs) binning_.target_chunks = 2 * threads;
  strays_.resize(threads);
  scratch_.resize(threads);
  for (auto& s : scratch_) s = std::make_unique<StressScratch>();

  node_mass_floor_ = check_start_and_mass_floor(grid_, view<D>(particles_));
  sort_particles();

  // Initial energies and the first stable time step.
  const double speed = start_balance<D>(view<D>(particles_), materials_, balance_);
  total0_ = balance_.leapfrog_total = balance_.total();
  energy_scale_ = std::max(std::abs(total0_), balance_.kinetic);
  const double h = grid_.min_cell_size();
  stable_dt_ = std::min(dt_max_, speed > 0 ? cfl_ * h / speed : dt_max_);
}

template <class GridT>
ExplicitSolver<GridT>::~ExplicitSolver() = default;

template <class GridT>
std::size_t ExplicitSolver<GridT>::work_bytes() const {
  std::size_t b = grid_.nodes() * (sizeof(double) + 3 * sizeof(Vec<D>) + (has_rigid_ ? 1 : 0));
  for (const auto& g : private_)
    b += g.m.capacity() * sizeof(double) +
         (g.v.capacity() + g.a.capacity() + g.q.capacity()) * sizeof(Vec<D>);
  for (const auto& pi : pindex_) b += pi.capacity() * sizeof(std::uint32_t);
  b += binning_.bins().capacity() * sizeof(Bin) + binning_.chunks().capacity() * sizeof(Chunk);
  return b;
}

template <class GridT>
void ExplicitSolver<GridT>::sort_particles() {
  ScopedTimer timer(timers_, timers_.id("sort"));
  removed_count_ += account_exits<D>(particles_, exits_, balance_);
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
        std::snprintf(where, sizeof where, "left the domain at (%.4g, %.4g, %.4g) m", p.x[i][0],
                      p.x[i][1], D == 3 ? p.x[i][D - 1] : 0.0);
        throw InstabilityError(
            steps_ + 1, time_ + dt_, p.id[i],
            std::string(where) + " (enlarge grid.domain, or set solver.on_exit = \"remove\")");
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
    case Where::OutsideDomain:
      s.exits.push_back(i);
      break;
    case Where::OutsideWindow:
      s.out_of_window = true;
      break;
    case Where::Window:
      if (key != bin_key) {
        ++s.off_bin;
        if (grid_.layer(key) != grid_.layer(bin_key)) ++s.strays;
      }
      break;
  }
}

// ------------------------------------------------------------------------------------------
// Scatter driver: how particles write to nodes without races (ScatterStrategy). A scatter
// kernel gives two bodies: bin_body(chunk, bin, target, strays) runs one bin with its cell's
// nodes cached in registers; a particle outside its bin's slab layer goes to `strays` (when
// not null) and later to particle_body(i, target, first_visit, chunk), which also serves the
// patch strategy (first_visit: the particle's own update is still to do).

template <class GridT>
template <class BinBody, class ParticleBody>
void ExplicitSolver<GridT>::scatter(int fields, BinBody&& bin_body, ParticleBody&& particle_body) {
  const auto& chunks = binning_.chunks();
  const int nchunks = binning_.chunk_count();
  const Target global{grid_.m.data(), grid_.v.data(), grid_.a.data(), grid_.v_remap.data(), 0};
  auto run_chunk = [&](int ch, const Target& t, std::vector<std::uint32_t>* strays) {
    for (std::uint32_t bi = chunks[ch].bin_begin; bi < chunks[ch].bin_end; ++bi)
      bin_body(ch, bi, t, strays);
  };
  // Private arrays: clear the fields this scatter writes; add them into the grid afterwards.
  auto clear = [&](PrivateGrid& g) {
    const std::size_t n = std::size_t(g.size);
    if (fields & kMass) g.m.assign(n, 0.0);
    if (fields & kMomentum) g.v.assign(n, Vec<D>::Zero());
    if (fields & kForce) g.a.assign(n, Vec<D>::Zero());
    if (fields & kRemap) g.q.assign(n, Vec<D>::Zero());
  };
  auto target = [&](PrivateGrid& g) {
    return Target{g.m.data(), g.v.data(), g.a.data(), g.q.data(), g.offset};
  };
  auto add_node = [&](const PrivateGrid& g, std::int64_t n) {
    const std::int64_t k = n - g.offset;
    if (fields & kMass) grid_.m[n] += g.m[k];
    if (fields & kMomentum) grid_.v[n] += g.v[k];
    if (fields & kForce) grid_.a[n] += g.a[k];
    if (fields & kRemap) grid_.v_remap[n] += g.q[k];
  };

  switch (strategy_) {
    case ScatterStrategy::Colored:
    case ScatterStrategy::LRSlabs: {
      // Two chunks of one colour never share a node: run a colour at a time. LR slabs give
      // thread t the chunks 2t (L) and 2t + 1 (R), statically.
      const bool lr = strategy_ == ScatterStrategy::LRSlabs;
#pragma omp parallel
      {
        auto& strays = strays_[omp_get_thread_num()];
        strays.clear();
        for (int color = 0; color < 2; ++color) {
          if (lr) {
#pragma omp for schedule(static, 1)
            for (int ch = color; ch < nchunks; ch += 2) run_chunk(ch, global, &strays);
          } else {
#pragma omp for schedule(dynamic, 1)
            for (int ch = color; ch < nchunks; ch += 2) run_chunk(ch, global, &strays);
          }
        }
      }
      std::vector<std::uint32_t> all;
      for (auto& st : strays_) all.insert(all.end(), st.begin(), st.end());
      std::sort(all.begin(), all.end());  // serially, in particle order
      for (auto i : all) particle_body(i, global, false, -1);
      break;
    }
    case ScatterStrategy::ArrayExpansion: {
      const int threads = omp_get_max_threads();
      private_.resize(threads);
      const std::int64_t n = std::int64_t(grid_.nodes());
#pragma omp parallel
      {
        PrivateGrid& mine = private_[omp_get_thread_num()];
        mine.offset = 0;
        mine.size = n;
        clear(mine);
        const Target t = target(mine);
#pragma omp for schedule(static)
        for (int ch = 0; ch < nchunks; ++ch) run_chunk(ch, t, nullptr);
          // A(:) = sum_j A_list(:, j) (000, eq. 16), in thread order at every node.
#pragma omp for schedule(static)
        for (std::int64_t node = 0; node < n; ++node)
          for (int j = 0; j < threads; ++j) add_node(private_[j], node);
      }
      break;
    }
    case ScatterStrategy::Patch: {
      if constexpr (requires { grid_.layer_stride(); }) {
        // Uniform patches along the slab axis, one per thread (000, section 4.1.2). Pindex and
        // patnp are rebuilt each scatter from the particles' current cells, in parallel:
        // patnp_th(j, p) counts particles of patch p in thread j's share.
        const int np = omp_get_max_threads();
        const int layers = grid_.layers();
        const std::int64_t S = grid_.layer_stride();
        const ParticleView<D> pv = view<D>(particles_);
        const std::size_t n = pv.n;
        std::vector<std::uint16_t> patch_of(n);
        std::vector<std::vector<std::size_t>> patnp_th(np, std::vector<std::size_t>(np, 0));
        // Patch pp holds the cell layers [pp layers / np, (pp + 1) layers / np).
        std::vector<std::uint16_t> patch_of_layer(layers);
        for (int pp = 0; pp < np; ++pp)
          for (int l = pp * layers / np; l < (pp + 1) * layers / np; ++l)
            patch_of_layer[l] = std::uint16_t(pp);
        pindex_.resize(np);
#pragma omp parallel
        {
          const int j = omp_get_thread_num();
#pragma omp for schedule(static)
          for (std::size_t i = 0; i < n; ++i) {
            std::int64_t key;
            Vec<D> xi;
            grid_.locate(pv.x[i], key, xi);
            const int pp = patch_of_layer[grid_.layer(key)];
            patch_of[i] = std::uint16_t(pp);
            ++patnp_th[j][pp];
          }
#pragma omp single
          for (int pp = 0; pp < np; ++pp) {
            std::size_t patnp = 0;
            for (int jj = 0; jj < np; ++jj) {
              const std::size_t c = patnp_th[jj][pp];
              patnp_th[jj][pp] = patnp;  // becomes thread jj's first slot in Pindex(:, pp)
              patnp += c;
            }
            pindex_[pp].resize(patnp);
          }
#pragma omp for schedule(static)
          for (std::size_t i = 0; i < n; ++i)
            pindex_[patch_of[i]][patnp_th[j][patch_of[i]]++] = std::uint32_t(i);
        }
        private_.resize(np);
#pragma omp parallel for schedule(static, 1)
        for (int pp = 0; pp < np; ++pp) {
          PrivateGrid& g = private_[pp];
          const std::int64_t l0 = std::int64_t(pp) * layers / np,
                             l1 = std::int64_t(pp + 1) * layers / np;
          g.offset = l0 * S;
          g.size = std::min<std::int64_t>((l1 + 1) * S, std::int64_t(grid_.nodes())) - g.offset;
          clear(g);
          const Target t = target(g);
          for (auto i : pindex_[pp]) particle_body(i, t, true, pp);
        }
        // Assemble the patches into the grid, patch by patch (neighbours share a node layer).
        for (int pp = 0; pp < np; ++pp) {
          const PrivateGrid& g = private_[pp];
#pragma omp parallel for schedule(static)
          for (std::int64_t k = 0; k < g.size; ++k) add_node(g, g.offset + k);
        }
      } else {
        throw InputError("--strategy", "the patch strategy needs a uniform grid");
      }
      break;
    }
  }
}

// Rigid particles mark the nodes they touch with their body, serially:
// they are few, and a node touched by two rigid bodies then takes the later one's mark.
template <class GridT>
void ExplicitSolver<GridT>::mark_rigid_nodes() {
  const ParticleView<D> p = view<D>(particles_);
  for (std::size_t i = 0; i < p.n; ++i) {
    if (p.material[i] != kRigidMaterial) continue;
    std::int64_t key, nodes[NMAX];
    Vec<D> xi;
    double N[NMAX];
    grid_.locate(p.x[i], key, xi);
    grid_.values(key, xi, N);
    const int nn = grid_.cell_nodes(key, nodes);
    for (int c = 0; c < nn; ++c)
      if (N[c] > 0) grid_.rigid[nodes[c]] = std::uint8_t(p.body[i] + 1);
  }
}

// ------------------------------------------------------------------------------------------
// Particle to grid (000, eqs. 1-5): lumped mass, momentum, internal force, body forces and
// loads. A particle in its bin's cell adds into registers flushed once per cell.

template <class GridT>
template <int F>
void ExplicitSolver<GridT>::p2g() {
  ScopedTimer timer(timers_, timers_.id(F == kForce    ? "p2g_force"
                                        : (F & kForce) ? "p2g"
                                                       : "p2g_mass_momentum"));
  constexpr bool kM = F & kMass, kP = F & kMomentum, kF = F & kForce;
  if constexpr (kM) {
    grid_.clear(scheme_ == Scheme::MUSL, has_rigid_);
    if (has_rigid_) mark_rigid_nodes();
  }
  const ParticleView<D> p = view<D>(particles_);
  material_ = p.material;
  const auto& bins = binning_.bins();
  const Vec<D> b = gravity_;
  const bool axi = axisymmetric_;

  // Contribution of particle i (cell `key`, local coordinates xi) through add(c, dm, dp, df).
  auto contribute = [&](std::uint32_t i, std::int64_t key, const Vec<D>& xi, int nn, auto&& add) {
    double N[NMAX];
    Vec<D> G[NMAX];
    if constexpr (kF)
      grid_.shape(key, xi, N, G);
    else
      grid_.values(key, xi, N);
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
        df = N[c] * fb - Vsigma * G[c];      // (000, eqs. 4-5)
        if (axi) df[0] -= Vs_hoop_r * N[c];  // hoop stress (Sulsky & Schreyer 1996)
      }
      add(c, m_p * N[c], N[c] * mv_p, df);
    }
  };
  // Writes into a target at the nodes of a cell.
  auto to_target = [&](const Target& t, const std::int64_t* nodes) {
    return [&t, nodes](int c, double dm, const Vec<D>& dp, const Vec<D>& df) {
      const std::int64_t n = nodes[c] - t.offset;
      if constexpr (kM) t.m[n] += dm;
      if constexpr (kP) t.v[n] += dp;
      if constexpr (kF) t.a[n] += df;
    };
  };
  auto particle_body = [&](std::uint32_t i, const Target& t, bool, int) {
    if (rigid(i)) return;
    std::int64_t key, nodes[NMAX];
    Vec<D> xi;
    grid_.locate(p.x[i], key, xi);
    const int nn = grid_.cell_nodes(key, nodes);
    contribute(i, key, xi, nn, to_target(t, nodes));
  };
  auto bin_body = [&](int, std::uint32_t bi, const Target& t, std::vector<std::uint32_t>* strays) {
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
      if (rigid(i)) continue;
      std::int64_t key;
      Vec<D> xi;
      locate_in_bin(bin.key, p.x[i], key, xi);
      if (key == bin.key) {
        contribute(i, key, xi, nn, to_cell);
      } else if (!strays || grid_.layer(key) == layer) {
        std::int64_t other[NMAX];
        const int nk = grid_.cell_nodes(key, other);
        contribute(i, key, xi, nk, to_target(t, other));
      } else {
        strays->push_back(i);
      }
    }
    for (int c = 0; c < nn; ++c) {
      const std::int64_t n = nodes[c] - t.offset;
      if constexpr (kM) t.m[n] += m_c[c];
      if constexpr (kP) t.v[n] += p_c[c];
      if constexpr (kF) t.a[n] += f_c[c];
    }
  };
  scatter(F, bin_body, particle_body);
}

// ------------------------------------------------------------------------------------------
// Grid kernels: nodal velocities and accelerations, boundary conditions (000, eq. 6), rigid
// bodies (the nodes they touch take their velocity, in every component for no-slip contact,
// in the components other than the `slip` axes otherwise; the force that takes is the force
// between material and body).

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
    const std::uint8_t held = rigid_held_[mark - 1];  // the other components slip
    for (int a = 0; a < D; ++a) {
      if (!(held >> a & 1)) continue;
      if (record_force) {
        const double F = grid_.m[i] * (vel[i][a] - vb[a]) / dt_;  // what the body pushes back
        rigid_force_[mark - 1][a] += F;
        balance_.external_work -= dt_ * F * vb[a];  // work of the body on the material
      }
      if (acc) (*acc)[i][a] += (vb[a] - vel[i][a]) / dt_;
      vel[i][a] = vb[a];
    }
  }
}

template <class GridT>
void ExplicitSolver<GridT>::momentum_to_velocity(std::vector<Vec<D>>& field) {
  const std::int64_t n = std::int64_t(grid_.nodes());
  const double floor = node_mass_floor_;
#pragma omp parallel for schedule(static)
  for (std::int64_t i = 0; i < n; ++i) {
    if (grid_.m[i] > floor)
      field[i] /= grid_.m[i];
    else if (!field[i].isZero())
      field[i].setZero();  // keep empty nodes at zero
  }
  apply_boundary(field, nullptr, false);
}

template <class GridT>
void ExplicitSolver<GridT>::grid_velocity() {
  ScopedTimer timer(timers_, timers_.id("grid_velocity"));
  momentum_to_velocity(grid_.v);
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
    } else if (!grid_.v[i].isZero() || !grid_.a[i].isZero()) {  // keep empty nodes at zero
      grid_.v[i].setZero();
      grid_.a[i].setZero();
    }
  }
  apply_boundary(grid_.v, &grid_.a, true);
}

template <class GridT>
void ExplicitSolver<GridT>::grid_remap() {
  ScopedTimer timer(timers_, timers_.id("grid_remap"));
  momentum_to_velocity(grid_.v_remap);
}

// ------------------------------------------------------------------------------------------
// Grid to particle: velocity (000, eqs. 8, 10), position when Move (eqs. 7, 9), and for MUSL
// the remapped momentum m_p v_p back to the grid (eq. 11), a scatter (see scatter()). Rigid
// particles keep their velocity and, when Move, advance with it.

template <class GridT>
template <bool Remap, bool Move>
void ExplicitSolver<GridT>::g2p() {
  ScopedTimer timer(timers_, timers_.id(Remap ? "g2p_remap" : Move ? "g2p_move" : "g2p"));
  const ParticleView<D> p = view<D>(particles_);
  material_ = p.material;
  const Vec<D>* a_i = grid_.a.data();
  const Vec<D>* v_i = grid_.v.data();
  const auto& bins = binning_.bins();
  const int nchunks = binning_.chunk_count();
  const double dt = dt_;
  const Vec<D> b = gravity_;
  std::vector<ChunkStats> stats(std::max(nchunks, omp_get_max_threads()));

  // The velocity (and position) update of particle i from nodal values at the nodes of its
  // cell; returns its shape function values in N for the remap.
  auto update = [&](std::uint32_t i, std::int64_t key, const Vec<D>& xi, const std::int64_t* nd,
                    int nk, const Vec<D>* a_c, const Vec<D>* v_c, double* N, ChunkStats& s,
                    std::int64_t bin_key) {
    grid_.values(key, xi, N);
    Vec<D> a_p = Vec<D>::Zero(), vbar = Vec<D>::Zero();
    for (int c = 0; c < nk; ++c) {
      a_p += N[c] * (a_c ? a_c[c] : a_i[nd[c]]);
      if constexpr (Move) vbar += N[c] * (v_c ? v_c[c] : v_i[nd[c]]);
    }
    const Vec<D> v_old = p.v[i];
    p.v[i] += dt * a_p;  // (000, eq. 8)
    s.leapfrog_kinetic += 0.5 * p.m[i] * v_old.dot(p.v[i]);
    if constexpr (Move) {
      p.x[i] += dt * vbar;  // (000, eq. 7)
      s.kinetic += 0.5 * p.m[i] * p.v[i].squaredNorm();
      for (int a = 0; a < D; ++a) s.momentum[a] += p.m[i] * p.v[i][a];
      s.work += dt * (p.m[i] * b + (p.f_ext ? p.f_ext[i] : Vec<D>::Zero())).dot(p.v[i]);
      track_move(p.x[i], i, bin_key, s);
    }
  };
  auto move_rigid = [&](std::uint32_t i, ChunkStats& s, std::int64_t bin_key) {
    if constexpr (Move) {
      p.x[i] += dt * p.v[i];
      track_move(p.x[i], i, bin_key, s);
    }
  };
  // One particle on its own: update (when first visited) and remap into a target.
  auto particle_body = [&](std::uint32_t i, const Target& t, bool first_visit, int unit) {
    std::int64_t key, nd[NMAX];
    Vec<D> xi;
    grid_.locate(p.x[i], key, xi);
    if (first_visit && rigid(i)) {
      move_rigid(i, stats[unit], key);
      return;
    }
    if (rigid(i)) return;
    const int nk = grid_.cell_nodes(key, nd);
    double N[NMAX];
    if (first_visit)
      update(i, key, xi, nd, nk, nullptr, nullptr, N, stats[unit], key);
    else
      grid_.values(key, xi, N);
    if constexpr (Remap) {
      const Vec<D> mv = p.m[i] * p.v[i];
      for (int c = 0; c < nk; ++c) t.q[nd[c] - t.offset] += N[c] * mv;
    }
  };
  // One bin with its cell's nodal values cached.
  auto bin_body = [&](int ch, std::uint32_t bi, const Target& t,
                      std::vector<std::uint32_t>* strays) {
    ChunkStats& s = stats[ch];
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
        move_rigid(i, s, bin.key);
        continue;
      }
      std::int64_t key;
      Vec<D> xi;
      locate_in_bin(bin.key, p.x[i], key, xi);
      const bool home = key == bin.key;
      const int nk = home ? nn : grid_.cell_nodes(key, other);
      const std::int64_t* nd = home ? nodes : other;
      double N[NMAX];
      update(i, key, xi, nd, nk, home ? a_c : nullptr, home ? v_c : nullptr, N, s, bin.key);
      if constexpr (Remap) {
        const Vec<D> mv = p.m[i] * p.v[i];
        if (home) {
          for (int c = 0; c < nk; ++c) q_c[c] += N[c] * mv;
        } else if (!strays || grid_.layer(key) == layer) {
          for (int c = 0; c < nk; ++c) t.q[nd[c] - t.offset] += N[c] * mv;
        } else {
          strays->push_back(i);
        }
      }
    }
    if constexpr (Remap)
      for (int c = 0; c < nn; ++c) t.q[nodes[c] - t.offset] += q_c[c];
  };

  if constexpr (Remap) {
    scatter(kRemap, bin_body, particle_body);
  } else {  // a gather: any chunk on any thread
    const auto& chunks = binning_.chunks();
    const Target none{nullptr, nullptr, nullptr, nullptr, 0};
#pragma omp parallel for schedule(dynamic, 1)
    for (int ch = 0; ch < nchunks; ++ch)
      for (std::uint32_t bi = chunks[ch].bin_begin; bi < chunks[ch].bin_end; ++bi)
        bin_body(ch, bi, none, nullptr);
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
        blk.plane_stress = plane_stress_;
        blk.thickness = p.thickness ? p.thickness + i0 : nullptr;
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
          locate_in_bin(bin.key, p.x[i], key, xi);
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
          // A block is a contiguous run of one material and one cell size: a skipped rigid
          // particle ends it.
          if (int(p.material[i]) != mat || k == kBlock || i != i0 + std::uint32_t(k) ||
              h_cell != h_block) {
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
