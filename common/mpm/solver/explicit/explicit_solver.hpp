#pragma once
/// Explicit MPM: USF, USL and MUSL with leapfrog time integration (000, section 2;
/// 004, sections 2 and 3.4), in 3D, 2D plane strain, plane stress and axisymmetry, on any grid
/// (the Grid concept of grid.hpp): the uniform window here, sparse_solver.hpp and
/// graded_solver.hpp for the others. The time step, ExplicitSolver::step, is at the top of
/// explicit_solver_impl.hpp; the kernels are in the files named after them.
#include <array>
#include <cstdint>
#include <memory>
#include <type_traits>
#include <vector>

#include "mpm/grid/grid.hpp"
#include "mpm/grid/sparse_grid.hpp"
#include "mpm/scene/scene.hpp"
#include "mpm/solver/core.hpp"
#include "mpm/solver/explicit/contact_fields.hpp"
#include "mpm/solver/explicit/lanes.hpp"
#include "mpm/solver/explicit/rebar.hpp"
#include "mpm/solver/explicit/scatter.hpp"

namespace mpm {

template <Grid GridT>
class ExplicitSolver : public SolverCore<GridT> {
  using Core = SolverCore<GridT>;

 public:
  static constexpr int D = GridT::kDim;

  /// Takes the particles (columns as written by mpm-prep; state columns are added) and a grid
  /// built for the scene. The columns are reordered into cell order and stay owned by the
  /// caller.
  ExplicitSolver(const Scene& scene, GridT grid, ColumnStore& particles,
                 ScatterStrategy strategy = ScatterStrategy::Colored);
  ~ExplicitSolver();

  /// One time step of size dt (at most stable_dt()). Throws InstabilityError. dt_pace (s) is
  /// the step the run would have taken had it not shortened this one to land on a frame time
  /// (0: dt); the leapfrog energy is evaluated at it, so that a shortened step does not make
  /// it jump (balance().leapfrog_total).
  void step(double dt, double dt_pace = 0);

  /// The largest stable step for the current state: cfl * h / max_p(c_p + |v_p|) (and dt_max).
  double stable_dt() const { return stable_dt_; }
  /// Particles split into 2^D children so far (graded grids, 004 section 3.3).
  long splits() const { return split_count_; }
  ScatterStrategy strategy() const { return scatter_.strategy(); }
  /// Force (N) on the first body of each [[contact]] pair from the second in the last step
  /// (per metre in plane strain, per radian in axisymmetry), in the order of Scene::contacts.
  const std::vector<Vec3>& contact_force() const { return contact_.force(); }
  /// Takes the rebar's element table (rebar_elements.hpp; a model's REBR record) before the
  /// first step: it stays the caller's and is updated in place; the first stable step then
  /// includes the elements' (L / sqrt(E / rho)). Throws InputError for a table the scene
  /// does not match.
  void attach_rebar(ColumnStore& elements);
  /// Rebar elements eroded so far (0 without rebar).
  std::size_t eroded_elements() const { return rebar_sums_.eroded; }
  /// The state between steps beyond the particle columns (SolverCore's, the stable step and
  /// the split counters); restore on a solver built from the columns saved with it.
  void save_state(StateValues& s) const;
  void restore_state(const StateValues& s);
  /// Bytes held by the solver beyond the particle columns: grid window, private scatter
  /// arrays, sort scratch and bins.
  std::size_t work_bytes() const;

 private:
  static constexpr int NMAX = GridT::kMaxNodes;
  /// The grid has ghost nodes beyond the domain's faces (B-spline grids).
  static constexpr bool kGhosts = requires(const GridT& g) { g.ghost_nodes(); };
  /// The grid gives APIC's node offsets and affine weights (uniform, sparse, B-spline).
  static constexpr bool kAffine = requires(const GridT& g, std::int64_t k, const Vec<D>& xi,
                                           const double* N, const Vec<D>* G, Vec<D>* W) {
    g.offsets(k, xi, W);
    g.affine_weights(k, xi, N, G, W);
  };
  using Target = ScatterTarget<D>;
  /// What grid_.v holds when grid_update runs: velocities (grid_velocity ran) or momenta.
  enum class NodeV { Velocity, Momentum };
  /// What g2p updates: the particle velocities; also the positions; or also the remapped
  /// momentum m_p v_p, scattered to the grid (MUSL).
  enum class G2pMode { Velocity, Move, Remap, Pic };
  /// Whether the stress update also advances the positions.
  enum class Positions { Stay, Move };
  /// Which nodal velocities a contact exchange corrects: grid velocities (USF, before the
  /// stress), updated velocities with their accelerations and the contact forces, or the
  /// remapped velocities (MUSL).
  enum class Exchange { Velocity, Update, Remap };
  /// What a particle kernel changed, for finish (bits).
  enum Changed { kVelocities = 1, kStresses = 2, kPositions = 4 };

  // Kernels, in the order a step uses them, each in the file named after it: p2g.hpp,
  // grid_update.hpp (grid_velocity, grid_update, grid_remap), g2p.hpp, stress.hpp and
  // graded_split.hpp (split_particles); with [[contact]], the grid kernels end with the
  // momentum exchange between the bodies' fields (contact.hpp). The particle kernels come in
  // two builds, C: the scene has contact (each particle of a body in contact uses its body's
  // field), or not (no contact code in the loop).
  template <int F>
  void p2g();
  void grid_velocity();
  void grid_update(NodeV in_v);
  void grid_remap();
  template <G2pMode M>
  void g2p();
  void update_stress(const std::vector<Vec<D>>& v_grad, Positions positions);
  void average_damage();  ///< HJC with damage_length: the step's increments averaged, added
  void exchange_momentum(Exchange on);
  void mirror_slip_normals();  ///< contact normals on the slip faces (contact.hpp, "Symmetry")
  void split_particles() requires GridT::kGraded;
  void rebar_forces();

  // The particle kernels' builds with and without contact.
  template <int F, bool C>
  void scatter_to_grid();
  template <G2pMode M, bool C>
  void gather_from_grid();
  /// A particle of a body in contact in a bin's scatter: add_to_field, or a stray.
  template <int F>
  void add_in_bin(const ParticleView<D>& p, std::uint32_t i, int f, std::int64_t bin_key,
                  std::int64_t key, const Vec<D>& xi, const std::int64_t* nodes, int nn, int layer,
                  std::vector<std::uint32_t>* strays);
  /// Particle i (of a body in contact, field f) adds mass, momentum, mass gradient (F has
  /// kMass) and force (F has kForce) to its field at the nodes nd of its cell `key`.
  template <int F>
  void add_to_field(const ParticleView<D>& p, std::uint32_t i, int f, std::int64_t key,
                    const Vec<D>& xi, const std::int64_t* nd, int nk);

  template <G2pMode M>
  void advance_in_field(const ParticleView<D>& p, std::uint32_t i, int f, std::int64_t key,
                        const Vec<D>& xi, const std::int64_t* nd, int nk, bool advance, bool remap,
                        ChunkSums& s, std::int64_t bin_key);

  // Helpers.
  void mark_rigid_nodes();
  /// Runs a scatter kernel by the strategy (scatter.hpp).
  template <class BinBody, class ParticleBody>
  void scatter(int fields, BinBody&& bin_body, ParticleBody&& particle_body) {
    const ParticleView<D> p = view<D>(particles_);
    scatter_.run(fields, grid_, binning_, p.x, p.n, bin_body, particle_body);
  }
  /// Cell and local coordinates of a particle of the bin of cell `bin_key`: a graded grid
  /// first tries that cell (GradedGrid::in_cell, the same result as locate without the tree
  /// search); a uniform grid's locate is as cheap as that test.
  [[gnu::always_inline]] void locate_in_bin(std::int64_t bin_key, const Vec<D>& x,
                                            std::int64_t& key, Vec<D>& xi) const {
    if constexpr (requires { grid_.in_cell(x, bin_key, xi); }) {
      if (grid_.in_cell(x, bin_key, xi)) {
        key = bin_key;
        return;
      }
    }
    grid_.locate(x, key, xi);
  }
  /// A particle of a bin: its cell and local coordinates (the bin's, when it is still there).
  [[gnu::always_inline]] void locate_in_bin(const Bin& bin, const Vec<D>& x, std::int64_t& key,
                                            Vec<D>& xi) const {
    if constexpr (kTrilinear) {
      if (grid_.in_cell(bin.cell.data(), x, xi)) {  // the same answer and xi as locate
        key = bin.key;
        return;
      }
    }
    locate_in_bin(bin.key, x, key, xi);
  }
  /// A particle of a bin, located: its cell and local coordinates there, and that cell's nodes.
  struct InBin {
    std::int64_t key;
    Vec<D> xi;
    bool home;               ///< still in the bin's cell
    int nk;                  ///< nodes of its cell
    const std::int64_t* nd;  ///< the bin's nodes at home, else `other` (filled)
  };
  [[gnu::always_inline]] InBin locate_in_bin(const Bin& bin, const std::int64_t* nodes, int nn,
                                             const Vec<D>& x, std::int64_t* other) const {
    InBin at;
    locate_in_bin(bin, x, at.key, at.xi);
    at.home = at.key == bin.key;
    at.nk = at.home ? nn : grid_.cell_nodes(at.key, other);
    at.nd = at.home ? nodes : other;
    return at;
  }
  void fold_ghosts(int fields);
  void sum_shared(int fields);
  void reduce_support_forces(double work_before);
  /// Under mpirun: every rank's sums added (rank order), and a fault on any rank thrown on all;
  /// returns whether particles left the domain on any rank since the last sort.
  bool reduce_ranks(ChunkSums& total, const InstabilityError* fault);
  [[noreturn]] void throw_rank_fault(const InstabilityError* fault);
  /// v = p / m at the nodes with mass, zero elsewhere, for one field's arrays.
  void momentum_to_velocity(const double* m, Vec<D>* field);
  /// One field's grid update: v_i = (p_i or v_i) + dt f_i / m_i, a_i = f_i / m_i.
  void integrate_nodes(const double* m, Vec<D>* v, Vec<D>* a, NodeV in_v);
  /// The boundary conditions and rigid bodies on every field's velocities (on: which ones).
  void apply_boundary(Exchange on);
  /// Holds one field's velocities (and accelerations, recording the forces, when acc).
  void hold_nodes(const double* m, Vec<D>* vel, Vec<D>* acc);
  template <G2pMode M>
  void advance_particle(const ParticleView<D>& p, std::uint32_t i, std::int64_t key,
                        const Vec<D>& xi, const std::int64_t* nd, int nk, const Vec<D>* a_c,
                        const Vec<D>* v_c, double* N, ChunkSums& s, std::int64_t bin_key,
                        double& leapfrog) const;
  /// A trilinear bin's corner accelerations and velocities as vectors (x, y, z, 0).
  struct CornerVectors {
    lanes::V4 a[8], v[8];
    void set(const Vec<D>* a_c, const Vec<D>* v_c) {
      if constexpr (D == 3)
        for (int c = 0; c < 8; ++c) {
          a[c] = lanes::V4{a_c[c][0], a_c[c][1], a_c[c][2], 0.0};
          if (v_c) v[c] = lanes::V4{v_c[c][0], v_c[c][1], v_c[c][2], 0.0};
        }
    }
  };
  template <G2pMode M>
  void advance_in_cell(const ParticleView<D>& p, std::uint32_t i, std::int64_t key,
                       const Vec<D>& xi, const CornerVectors& cv, double* N, ChunkSums& s,
                       std::int64_t bin_key, double& leapfrog) const;
  template <G2pMode M>
  void update_particle(const ParticleView<D>& p, std::uint32_t i, const Vec<D>& a_p,
                       const Vec<D>& vbar, ChunkSums& s, std::int64_t bin_key,
                       double& leapfrog) const;
  void stress_block(const ParticleView<D>& p, PendingBlock& pb, StressScratch& scr, ChunkSums& s,
                    bool rows, bool motion) const;
  /// A particle without stress in the stress pass: a rigid one advances with its own
  /// velocity, a rebar node with the grid's (v_c: its bin's cached nodal velocities or null).
  [[gnu::noinline, gnu::cold]] void move_unstressed(const ParticleView<D>& p, std::uint32_t i,
                                                    const Bin& bin, const std::int64_t* nodes,
                                                    int nn, const Vec<D>* v_c, ChunkSums& s);
  template <bool C>
  void stress_chunk(const ParticleView<D>& p, int ch, const Vec<D>* vg_i, Positions positions,
                    bool remapped, ChunkSums& s);
  template <bool C>
  void general_sums(const ParticleView<D>& p, std::uint32_t i, const Bin& bin,
                    const std::int64_t* nodes, int nn, std::int64_t* other, const Vec<D>* vg_i,
                    const Vec<D>* v_c, const Vec<D>* vg_c, bool move, bool remapped, Mat<D>& L,
                    Vec<D>& vbar, double& v_r);
  /// Uniform and sparse 3D cells: trilinear shape functions, whose sums trilinear_sums takes
  /// across the particles of a bin (stress.hpp).
  static constexpr bool kTrilinear =
      std::is_same_v<GridT, UniformGrid<3>> || std::is_same_v<GridT, SparseGrid<3>>;
  /// The velocity gradients (L(r, c) in L[3 r + c]) and move velocities of a bin's particles,
  /// one array per component, and which of them are still in the bin's cell.
  struct TrilinearBin {
    static constexpr int kMax = 32;   ///< larger bins take the general sums
    static constexpr int kLanes = 8;  ///< AVX-512's doubles (twice AVX2's): kMax's divisor
    /// Lanes a bin's loops run: n rounded up to whole vectors.
    static int lanes(int n) { return (n + kLanes - 1) / kLanes * kLanes; }
    alignas(64) double x[3][kMax];  ///< local coordinates in the bin's cell
    alignas(64) double L[9][kMax];
    alignas(64) double v[3][kMax];
    std::int64_t home[kMax];  ///< 1 in the cell (64 bits: whole vectors of doubles)
  };
  void trilinear_sums(const ParticleView<D>& p, const Bin& bin, const Vec<D>* vg, const Vec<D>* v,
                      TrilinearBin& tb) const;
  template <bool Xi>
  int cell_lanes(const ParticleView<D>& p, const Bin& bin, TrilinearBin& tb) const;
  void track_bin(const ParticleView<D>& p, const Bin& bin, TrilinearBin& tb, ChunkSums& s) const;
  /// p2g's sums over a bin's particles in its cell (p2g.hpp): mass and momentum and body force
  /// by corner, the stress by axis, component and edge along the axis.
  struct TrilinearSums {
    lanes::V8 m, p[3], b[3];  ///< by corner (lanes.hpp)
    lanes::V4 s[3][3];        ///< by axis, component, edge
  };
  template <int F>
  void trilinear_add(const ParticleView<D>& p, std::uint32_t i, const Vec<D>& xi,
                     TrilinearSums& ts) const;
  template <int F>
  void trilinear_corners(const TrilinearSums& ts, double* m_c, Vec<D>* p_c, Vec<D>* f_c) const;
  struct SplitScan;
  SplitScan scan_for_splits() requires GridT::kGraded;
  void write_children(const SplitScan& scan, std::size_t n) requires GridT::kGraded;
  void finish(std::vector<ChunkSums>& stats, int changed);
  void leapfrog_balance(double dt, double dt_pace, double internal_start, double kinetic_start);

  using Core::axisymmetric_, Core::balance_, Core::binning_, Core::dt_, Core::exits_,
      Core::face_force_, Core::gravity_, Core::grid_, Core::has_rigid_, Core::material_,
      Core::materials_, Core::need_sort_, Core::node_mass_floor_, Core::particles_,
      Core::plane_stress_, Core::rigid_force_, Core::rigid_held_, Core::rigid_mark_,
      Core::marked_body_, Core::rigid_velocity_, Core::scene_, Core::scratch_, Core::steps_,
      Core::time_, Core::timers_, Core::ranks_;
  using Core::book_rigid_force, Core::reduce, Core::rigid, Core::sort_particles, Core::track_move,
      Core::update_block;

  Scheme scheme_;
  Scatter<GridT> scatter_;
  ContactFields<D> contact_;  ///< the bodies' own fields ([[contact]]); inactive without
  RebarTruss<D> rebar_;       ///< truss elements ([[rebar]]); inactive without
  RebarSums rebar_sums_;      ///< of the last element pass
  long rebar_linked_ = -1;    ///< the sort the rebar's node indices were found after
  double cfl_, dt_max_;
  double stable_dt_ = 0;
  double leapfrog_kinetic_ = 0;  ///< sum m v(k-1/2).v(k+1/2) / 2 of the last step
  bool loads_ = false;           ///< a body force or loads act (their work is booked)
  double load_work_ = 0;         ///< J: their work in the last step (ChunkSums::work)
  double load_work_start_ = 0;   ///< J: its part at the velocities before the step
  std::uint32_t next_id_ = 0;    ///< id of the next particle a split creates (0: not yet known)
  long split_count_ = 0;         ///< particles split so far
  int split_wait_ = 0;           ///< steps the pending splits have waited for a sort
  /// HJC materials with a damage_length (damage_average.hpp): their indices, a flag by
  /// material, the step's local increments by particle, and the lattice's scratch.
  std::vector<int> averaged_;
  std::vector<std::uint8_t> averaged_by_mat_;
  mutable std::vector<double> damage_increment_;
  std::vector<double> lattice_q_, lattice_m_;
};

/// The uniform-grid solver of a scene: builds the window grid on the scene's lattice.
template <int D>
using UniformSolver = ExplicitSolver<UniformGrid<D>>;

}  // namespace mpm
