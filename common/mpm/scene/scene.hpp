#pragma once
/// The scene: what the user describes in a TOML file (reference: docs/scene.md). Every string
/// is parsed into an enum or a typed SI value here, once; nothing past the parser sees text.
#include <array>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "mpm/core/columns.hpp"
#include "mpm/core/types.hpp"

namespace mpm {

/// Where a value came from, for error messages ("scene.toml:12", or "--set solver.cfl").
struct SourceLoc {
  std::string file;
  int line = 0;
  std::string key;  ///< dotted path, e.g. "materials.copper.density"
};

enum class StrengthModel { Elastic, J2, JohnsonCook, Bilinear, Hjc };
enum class EosModel { Linear, MieGruneisen, Tillotson, Hjc };

/// Deviatoric strength. J2: sigma_y = A + B eps_p^n. Johnson-Cook multiplies by
/// (1 + C ln(rate/rate0)) (1 - T*^m), T* = (T - T_room)/(T_melt - T_room). Bilinear: J2 with
/// sigma_y = A + H eps_p, H = E E_T / (E - E_T), so that the uniaxial curve bends from slope E
/// to slope E_T at A.
struct StrengthSpec {
  StrengthModel model = StrengthModel::Elastic;
  double A = 0;                      ///< initial yield stress, Pa (bilinear: yield_stress)
  double B = 0;                      ///< hardening modulus, Pa
  double n = 1;                      ///< hardening exponent
  double C = 0;                      ///< strain-rate coefficient (Johnson-Cook)
  double reference_rate = 1.0;       ///< reference plastic strain rate, 1/s
  double m = 0;                      ///< thermal softening exponent; 0 means no thermal term
  double room_temperature = 293.0;   ///< K
  double melt_temperature = 1356.0;  ///< K
  double specific_heat = 383.0;      ///< J/(kg K)
  double taylor_quinney = 0.9;       ///< fraction of plastic work turned into heat
  double tangent_modulus = 0;        ///< bilinear: E_T, the uniaxial slope after yield, Pa
  bool thermal() const { return model == StrengthModel::JohnsonCook && m > 0; }
};

/// Tillotson's constants (docs/eos-tillotson.md); rho0 is the material's density.
struct TillotsonSpec {
  double a = 0, b = 0;         ///< thermal coefficients (a + b: Grueneisen's at rho0)
  double A = 0, B = 0;         ///< linear and quadratic compression moduli, Pa
  double E0 = 0;               ///< energy scale of omega = 1 + E / (E0 eta^2), J/kg
  double E_iv = 0, E_cv = 0;   ///< incipient and complete vaporisation energies, J/kg
  double alpha = 0, beta = 0;  ///< decay of the expanded branch's terms
};

/// Equation of state. Linear: p = K mu. Mie-Grueneisen (000, eq. 18) with internal energy.
/// Tillotson: compressed, cold and hot expanded branches (docs/eos-tillotson.md).
struct EosSpec {
  EosModel model = EosModel::Linear;
  double c0 = 0;      ///< bulk sound speed, m/s
  double s = 0;       ///< slope of the shock-particle velocity relation
  double gamma0 = 0;  ///< Grueneisen coefficient
  /// Mie-Grueneisen in expansion (mu < 0): p = rho0 c0^2 mu + gamma0 E as 000 eq. 18 prints it
  /// (true), or without the energy term, as the seed authors' own code does (false).
  bool energy_in_expansion = true;
  TillotsonSpec tillotson;  ///< model = Tillotson only
};

/// Failure: a failed particle keeps no deviatoric stress and carries no tension.
struct FailureSpec {
  double plastic_strain = std::numeric_limits<double>::infinity();  ///< eps_p at failure
  double pressure = -std::numeric_limits<double>::infinity();       ///< cut-off pressure, Pa
  bool enabled() const {
    return plastic_strain < std::numeric_limits<double>::infinity() ||
           pressure > -std::numeric_limits<double>::infinity();
  }
};

/// Holmquist-Johnson-Cook concrete (docs/scene.md, HJC concrete): its strength (strength.model
/// = "hjc") and its pressure (eos.model = "hjc") share these constants; the two go together.
struct HjcSpec {
  double A = 0, B = 0, N = 1;        ///< normalised cohesion, pressure hardening and its exponent
  double C = 0;                      ///< strain-rate coefficient
  double fc = 0;                     ///< quasi-static uniaxial compressive strength f'c, Pa
  double T = 0;                      ///< tensile strength, Pa
  double S_max = 0;                  ///< cap on the normalised strength
  double reference_rate = 1;         ///< 1/s
  double D1 = 0, D2 = 1;             ///< damage: fracture strain D1 (P* + T*)^D2
  double EF_min = 0;                 ///< least fracture strain
  double P_crush = 0, mu_crush = 0;  ///< end of the elastic region, Pa and -
  double P_lock = 0, mu_lock = 0;    ///< lock pressure (Pa), and the fully dense curve's p = 0
  double K1 = 0, K2 = 0, K3 = 0;     ///< fully dense curve, Pa
  /// How T follows the strain rate: None (HJC as published, T at every rate), or MalvarRoss
  /// (T times Malvar and Ross's 1998 dynamic increase factor of concrete in tension at the
  /// particle's largest principal strain rate, at most tension_dif_max).
  enum class TensionRate : std::uint8_t { None, MalvarRoss };
  TensionRate tension_rate = TensionRate::None;
  double tension_dif_max = std::numeric_limits<double>::infinity();
  /// m; 0: the damage of each particle from its own strains (as published). Else each step's
  /// damage increments are averaged, weighted by mass, over about this length each way (a
  /// lattice of this spacing, common/mpm/solver/damage_average.hpp) before they are added.
  double damage_length = 0;
  SourceLoc damage_length_loc;  ///< where damage_length was given (file line or --set)
  double K_elastic() const { return P_crush / mu_crush; }
};

struct MaterialSpec {
  std::string name;
  double density = 0;         ///< reference density rho_0, kg/m^3
  double youngs_modulus = 0;  ///< Pa
  double poisson_ratio = 0;   ///< -
  StrengthSpec strength;
  EosSpec eos;
  FailureSpec failure;
  HjcSpec hjc;  ///< strength.model or eos.model = Hjc (both or neither)
  SourceLoc loc;
  double shear_modulus() const { return youngs_modulus / (2 * (1 + poisson_ratio)); }
  double bulk_modulus() const { return youngs_modulus / (3 * (1 - 2 * poisson_ratio)); }
};

enum class ShapeKind { Box, Cylinder, Sphere, Mesh, Ogive };

/// A formula of position written in the scene (a body's velocity_field or stress_field), SI.
/// Its variables are field_variables(); "0" stands for an absent component.
struct FieldExpression {
  std::string text;
  SourceLoc loc;  ///< the key, e.g. "bodies.bar.velocity_field[0]"
};
/// The variables of field expressions, in the order prep binds them: x, y, z (m; z = 0 in 2D),
/// r (m, the distance from the centre of the body's bounding box), and that box, x_min, x_max,
/// y_min, y_max, z_min, z_max (m).
const std::vector<std::string>& field_variables();

/// A body: a shape in its local frame, placed by scale, then rotation, then translation.
/// Local frames: box centred on the origin; cylinder along +z from z = 0 to z = length,
/// axis through the origin; ogive (a shank and a tangent-ogive nose) along +z from its base at
/// z = 0 to its nose tip at z = length; sphere centred on the origin; mesh as in its file.
/// In 2D scenes the shapes live in the x-y plane: box is a rectangle, sphere a disk.
struct BodySpec {
  std::string name;
  int material = -1;  ///< index into Scene::materials
  ShapeKind shape = ShapeKind::Box;
  Vec3 size = Vec3::Zero();        ///< box edge lengths, m
  double radius = 0;               ///< cylinder or sphere, m; ogive: the shank's radius
  double length = 0;               ///< cylinder, m; ogive: overall, base to nose tip
  double crh = 0;                  ///< ogive: the nose's arc radius in shank diameters
  std::string mesh_path;           ///< STL, OFF or OBJ; relative paths are from the scene file
  Vec3 scale = Vec3::Ones();       ///< applied first
  Vec3 rotate_deg = Vec3::Zero();  ///< rotations about x, then y, then z, degrees
  Vec3 translate = Vec3::Zero();   ///< applied last, m
  Vec3 velocity = Vec3::Zero();    ///< initial velocity, m/s (rigid bodies: kept for ever)
  int particles_per_cell = 2;      ///< per axis: n x n x n particles in each cell
  /// Particle spacing, m, when given (particle_spacing): a lattice of its own, centred on the
  /// body, independent of the cells; 0: cell_size / particles_per_cell.
  double particle_spacing = 0;
  SourceLoc spacing_loc;  ///< where particle_spacing was given (file line or --set)
  /// The body's particle spacing on cells of size h.
  double spacing(double h) const {
    return particle_spacing > 0 ? particle_spacing : h / particles_per_cell;
  }
  /// Initial spin and fields (docs/scene.md, initial fields): the particle at x starts at
  /// velocity + angular_velocity x (x - spin_centre) + velocity_field(x), stress stress_field(x).
  Vec3 angular_velocity = Vec3::Zero();         ///< rad/s (2D: z only)
  bool spin_centre_given = false;               ///< else the centre of the body's bounding box
  Vec3 spin_centre = Vec3::Zero();              ///< m
  std::vector<FieldExpression> velocity_field;  ///< one per axis, m/s; empty: none
  std::vector<FieldExpression> stress_field;    ///< xx yy zz yz xz xy (Voigt), Pa; empty: none
  bool has_initial_fields() const {
    return !angular_velocity.isZero(0) || !velocity_field.empty() || !stress_field.empty();
  }
  bool rigid = false;  ///< moves at `velocity` whatever happens
  /// Rigid bodies: bit a set = the contact is frictionless along axis a (the nodes the body
  /// touches keep the material's velocity in that component); 0 = no-slip (all components).
  std::uint8_t slip_axes = 0;
  /// The domain may cut the body (its part outside gets no particles); else mpm-prep refuses a
  /// body the domain cuts anywhere but at a symmetry plane.
  bool cut_by_domain = false;
  SourceLoc loc;
};

/// A constant force applied from t = 0 to the particles of a body inside a region (all of the
/// body when no region is given), shared equally among them.
struct LoadSpec {
  int body = -1;  ///< index into Scene::bodies
  Vec3 force =
      Vec3::Zero();  ///< total force, N (plane strain: N per metre; axisymmetric: whole ring)
  bool region_given = false;
  Vec3 region_min = Vec3::Zero();  ///< m, initial positions
  Vec3 region_max = Vec3::Zero();
  SourceLoc loc;
};

/// Contact between two deformable bodies (004, section 5.4; Bardenhagen et al. 2001): each
/// body of a pair gets its own velocity field at the nodes it shares with the other; where the
/// fields approach, their normal velocities are made equal and the tangential part obeys
/// Coulomb friction; where they separate they stay free. Bodies in no pair share one field.
struct ContactSpec {
  int body_a = -1, body_b = -1;  ///< indices into Scene::bodies, as the pair names them
  double friction = 0;           ///< Coulomb coefficient, >= 0; 0 = frictionless
  /// Where the contact normal comes from at a node: the steeper of the two mass gradients,
  /// their difference (an average), or one body's (body_a or body_b: a smooth, hard
  /// penetrator's surface against a damaged target's ragged one).
  enum class Normal { Steeper, Average, BodyA, BodyB } normal = Normal::Steeper;
  /// The fields touch at a node when their mass centres there are closer than this, in cells
  /// of the node (Grid::node_cell_size), along the normal (undeformed touching bodies with two
  /// particles a cell per axis: 0.70 to 0.98).
  double gap = 1.5;
  /// When >= 0 (the scene's `separation`), the fields touch at a node when their surfaces
  /// there, estimated from the mass centres and the shares of the node's volume
  /// (touching_gap, contact_fields.hpp), are closer than this, in cells of the node;
  /// `gap` is then not used.
  double separation = -1;
  SourceLoc loc;  ///< key "contact.<index>"
};

/// A refined box of a graded grid (004, section 3.1): its cells are cell_size / 2^(level - 1)
/// across. Boxes are aligned to the lattice of the next coarser level and nested.
struct LevelSpec {
  int level = 2;            ///< 2, 3, ...; level 1 is the whole domain
  Vec3 min = Vec3::Zero();  ///< lower corner, m
  Vec3 max = Vec3::Zero();  ///< upper corner, m
  int follow = -1;  ///< index into Scene::bodies: the box moves with its mass centre; -1: fixed
  SourceLoc loc;    ///< key "grid.levels.<index>"
};

/// The grid's shape functions: multilinear on a cell's corners (the seeds'), or quadratic
/// B-splines on the 3 x 3 (x 3) nodes around a particle's nearest node (smooth gradients: no
/// cell-crossing noise, and a node's share of force stays in proportion to its share of mass).
enum class GridShape { Linear, Bspline };

struct GridSpec {
  double cell_size = 0;  ///< h, m
  GridShape shape = GridShape::Linear;
  bool domain_given = false;  ///< else fitted to the bodies with padding
  Vec3 domain_min = Vec3::Zero();
  Vec3 domain_max = Vec3::Zero();
  double padding = 0;             ///< m, added around the bodies when the domain is fitted
  std::vector<LevelSpec> levels;  ///< refined boxes of a graded grid; empty: a uniform grid
  /// Nodes only around the occupied cells (sparse_grid.hpp) instead of the dense window over
  /// the particles' bounding box: for material that spreads (debris clouds). Explicit solver,
  /// uniform grid.
  bool sparse = false;
  SourceLoc loc;
  /// Number of levels: 1 + the highest refinement (1 for a uniform grid).
  int level_count() const {
    int n = 1;
    for (const auto& l : levels) n = l.level > n ? l.level : n;
    return n;
  }
};

/// Reinforcing bars (004, section 2: HFEMP): truss elements whose nodes are particles.
enum class RebarShape { Bar, Layer, Polyline };

/// A [[rebar]] entry: one straight bar, a square-pattern layer of bars, or the polylines of a
/// file, of one section and one material, cut into truss elements by mpm-prep.
struct RebarSpec {
  RebarShape shape = RebarShape::Bar;
  int material = -1;  ///< index into Scene::materials: its density, E and yield stress
  /// Index into Scene::bodies: the body the bars lie in (their nodes count as its particles in
  /// histories and share its velocity field); default the first deformable body.
  int body = -1;
  double diameter = 0;        ///< m; the section is pi d^2 / 4
  double element_length = 0;  ///< m, at most; 0: half the cell size
  /// Plastic strain past which an element is eroded (removed; its nodes keep their mass);
  /// default the material's failure.plastic_strain, else none.
  double erosion_strain = std::numeric_limits<double>::infinity();
  Vec3 start = Vec3::Zero(), end = Vec3::Zero();  ///< bar: its end points, m
  /// Layer: the axis normal to its plane (0 x, 1 y, 2 z); the in-plane axes are a = normal + 1,
  /// b = normal + 2 (mod 3).
  int normal = 2;
  bool offset_given = false;
  double offset = 0;            ///< layer: the plane's coordinate along the normal, m
  double cover = 0;             ///< layer, without offset: body face to the bars' surface, m
  bool cover_from_max = false;  ///< layer: the cover is from the body's upper face
  double pitch = 0;             ///< layer: distance between neighbouring bars, m
  /// Layer: bars parallel to a (spaced along b), bars parallel to b (spaced along a).
  std::array<int, 2> count{0, 0};
  /// Layer: the in-plane coordinates (a, b) where the first bars of the two families cross;
  /// unset: the pattern is centred on the body's bounding box.
  bool first_given = false;
  std::array<double, 2> first{0, 0};
  std::string path;  ///< polyline: the file (relative to the scene's directory)
  SourceLoc loc;     ///< key "rebar.<index>"
};

enum class BoundaryType { Free, Slip, Fixed };
/// Faces in the order x_min, x_max, y_min, y_max, z_min, z_max.
struct BoundarySpec {
  std::array<BoundaryType, 6> face{BoundaryType::Free, BoundaryType::Free, BoundaryType::Free,
                                   BoundaryType::Free, BoundaryType::Free, BoundaryType::Free};
};

/// Explicit update schemes. APIC: the affine particle-in-cell transfer (Jiang et al. 2015),
/// which keeps angular momentum; each particle carries its velocity gradient C.
enum class Scheme { USF, USL, MUSL, APIC };
/// What happens to a particle that leaves the domain.
enum class OnExit { Stop, Remove };

/// Which solver advances the scene in time.
enum class SolverType { Explicit, Implicit };
/// Implicit unknowns: grid velocities (symmetric Jacobian, 001 section 2.4) or grid momenta
/// (non-symmetric, 001 section 3.2).
enum class Formulation { Velocity, Momentum };
/// Krylov method of the Newton step: conjugate gradients (symmetric) or GMRES.
enum class KrylovMethod { CG, GMRES };
/// Linear tolerance of each Newton step: fixed, or Eisenstat-Walker (choice 2).
enum class Forcing { Fixed, EisenstatWalker };
/// Newton's initial guess: the grid velocities (or momenta) from the particles, v^k (001,
/// Algorithm 1), or the previous step's converged grid velocities where a node had them.
enum class InitialGuess { Particles, Previous };
/// Preconditioner of the Krylov solve: none; the Jacobian's diagonal estimated from the
/// lumped mass and the elastic stiffness; or the whole tangent M + theta dt^2 K_t (the
/// elastic-plastic stiffness of the particles at the step's start), assembled and factored.
enum class Preconditioner { None, Diagonal, Tangent };

/// The implicit solver (001, sections 2.4 and 3.2): the theta-scheme of eq. 2.4.1 solved by
/// matrix-free Newton-Krylov with a backtracking line search. Defaults are the seed's.
struct ImplicitSpec {
  double theta = 1.0;  ///< mu of (001, eq. 2.4.1): 0 explicit, 1 fully implicit
  Formulation formulation = Formulation::Momentum;
  KrylovMethod krylov = KrylovMethod::GMRES;  ///< default: CG for velocity, GMRES for momentum
  double newton_tolerance = 1e-5;     ///< on ||F||_2 of the dimensionless residual (001 s. 3.2.2)
  double linear_tolerance = 1e-3;     ///< Krylov: ||J s + F|| <= eta ||F|| (fixed forcing)
  double derivative_step = 1e-5;      ///< h of the directional difference (001, eq. 2.4.18)
  int gmres_basis = 20;               ///< Krylov vectors kept by GMRES (001, section 3.2.4)
  int gmres_restarts = 0;             ///< restarts after a full basis (0: use the basis once)
  int max_krylov = 200;               ///< CG iterations per Newton step, at most
  int max_newton = 25;                ///< Newton iterations per step before the step is cut
  int max_line_search = 8;            ///< halvings of a Newton step before it counts as failed
  double dt_initial_multiple = 1.0;   ///< first step, in explicit (CFL) steps
  double dt_target_multiple = 100.0;  ///< largest step, in explicit steps
  double ramp = 0.2;                  ///< growth of the step per step (001 Tables 1-6: 20%)
  double cut = 0.5;                   ///< factor on the step after a failed Newton solve
  int max_cuts = 10;                  ///< cuts of one step before the run stops (exit 3)
  Forcing forcing = Forcing::EisenstatWalker;  ///< measured to win: examples/implicit/results.md
  /// Default by measurement too: diagonal for the velocity formulation (CG), none for the
  /// momentum formulation (GMRES), where the elastic diagonal slowed the plastic upsetting.
  Preconditioner preconditioner = Preconditioner::None;
  /// Default by measurement: previous for the velocity formulation (CG), particles for the
  /// momentum formulation (GMRES), where the contact of the upsetting made it slower.
  InitialGuess initial_guess = InitialGuess::Particles;
};

struct SolverSpec {
  SolverType type = SolverType::Explicit;
  ImplicitSpec implicit;  ///< used when type is Implicit
  Scheme scheme = Scheme::MUSL;
  double cfl = 0.5;                                         ///< dt = cfl * h / max(c + |v|)
  double end_time = 0;                                      ///< s
  double dt_max = std::numeric_limits<double>::infinity();  ///< s
  double bulk_linear = 0.06;    ///< artificial bulk viscosity, linear coefficient
  double bulk_quadratic = 1.5;  ///< artificial bulk viscosity, quadratic coefficient
  Vec3 gravity = Vec3::Zero();  ///< body force per unit mass, m/s^2
  OnExit on_exit = OnExit::Stop;
  double energy_growth_limit = 0.05;  ///< stop when total energy exceeds its reference by this
  long max_steps = 0;                 ///< 0: no limit
};

struct OutputSpec {
  int frames = 10;                  ///< frames written in (0, end_time], plus the initial one
  double history_interval = 0;      ///< s; 0: every step
  std::vector<std::string> fields;  ///< particle columns written in frames; empty: all
  Precision precision = Precision::Float64;
  double checkpoint_time = 0;  ///< s of simulated time between checkpoints; 0: none
  double checkpoint_wall = 0;  ///< s of wall-clock time between checkpoints; 0: none
  /// Per-body mass, momentum and energies in the history; unset: when the scene has 2 to
  /// kBodyHistoryAuto deformable bodies.
  std::optional<bool> body_history;
  static constexpr int kBodyHistoryAuto = 16;
};

struct Scene {
  std::string source;     ///< file name (or "<stream>") the scene was read from
  std::string directory;  ///< directory of the scene file, for relative mesh paths
  std::string title;
  int dimension = 3;          ///< 3, or 2 (x-y plane)
  bool axisymmetric = false;  ///< 2D only: x is the radius, y the axis; else plane strain
  bool plane_stress = false;  ///< 2D only: sigma_zz = 0, the thickness follows (thin sheets)
  std::vector<MaterialSpec> materials;
  std::vector<BodySpec> bodies;
  std::vector<LoadSpec> loads;
  std::vector<ContactSpec> contacts;  ///< body pairs in contact; empty: one velocity field
  std::vector<RebarSpec> rebars;      ///< reinforcing bars ([[rebar]]); empty: none
  GridSpec grid;
  BoundarySpec boundary;
  SolverSpec solver;
  OutputSpec output;
  std::string toml;  ///< the scene as TOML text after overrides, as stored in streams
  /// Values that are valid but implausible ("file:line: key: what and the likely fix"), found
  /// by the parser; mpm-prep prints them as warnings.
  std::vector<std::string> warnings;

  /// Index of a material by name, -1 if absent.
  int material_index(const std::string& name) const;
  /// Index of a body by name, -1 if absent.
  int body_index(const std::string& name) const;
  /// Factor from the computed quantities (per metre of thickness in plane strain, per radian
  /// in axisymmetry) to reported totals (whole revolution): 2 pi in axisymmetry, else 1.
  double measure_factor() const;
};

/// Parses a scene from TOML text. `source` names it in messages; `directory` resolves relative
/// mesh paths. `overrides` are "key=value" strings (--set) applied before validation; a value
/// is read as TOML, or as a string when it is not valid TOML ("0.38mm").
/// Throws InputError naming the file, line and key of the first mistake.
Scene parse_scene(const std::string& toml_text, const std::string& source,
                  const std::string& directory, const std::vector<std::string>& overrides);

/// Reads and parses a scene file ("-" for stdin). Throws InputError.
Scene load_scene(const std::string& path, const std::vector<std::string>& overrides);

}  // namespace mpm
