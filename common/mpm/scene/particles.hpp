#pragma once
/// Particles are named columns (structure of arrays) kept in cell order. Only the columns the
/// scene's materials need exist: no eps_p without plasticity, no T without thermal softening,
/// no failed flag without a failure model, no damage or mu_max without HJC concrete.
#include <cstdint>
#include <string>
#include <vector>

#include "mpm/core/columns.hpp"
#include "mpm/core/types.hpp"
#include "mpm/scene/scene.hpp"

namespace mpm {

/// Column names used by the tools (also the field names in frames and VTK files).
namespace col {
inline const std::string id = "id";              ///< u32, stable particle number
inline const std::string body = "body";          ///< u8 (u32 past 255 bodies), Scene::bodies
inline const std::string material = "material";  ///< u8, index into Scene::materials
inline const std::string x = "x";                ///< D x f64, position, m
inline const std::string v = "v";                ///< D x f64, velocity, m/s
inline const std::string m = "m";                ///< f64, mass, kg (per metre in 2D)
inline const std::string rho = "rho";            ///< f64, current density, kg/m^3
inline const std::string sigma = "sigma";        ///< 6 x f64, Cauchy stress (Voigt), Pa
inline const std::string e = "e";                ///< f64, specific internal energy, J/kg
inline const std::string eps_p = "eps_p";        ///< f64, equivalent plastic strain
inline const std::string T = "T";                ///< f64, temperature, K
inline const std::string failed = "failed";      ///< u8, 1 once the failure criterion was met
inline const std::string damage = "damage";      ///< f64, HJC damage D in [0, 1]
inline const std::string mu_max = "mu_max";      ///< f64, HJC: largest compression rho/rho0 - 1
inline const std::string f_ext = "f_ext";        ///< D x f64, applied force (loads), N
inline const std::string f_rebar = "f_rebar";    ///< D x f64, rebar elements' force on a node, N
inline const std::string strain = "strain";  ///< D x f64, accumulated normal strains (graded grids)
inline const std::string level =
    "level";                       ///< u8, grid level of the particle's spacing (graded grids)
inline const std::string C = "C";  ///< D x D f64, APIC's affine velocity (column-major), 1/s
inline const std::string thickness =
    "thickness";  ///< f64, thickness / initial thickness (plane stress)
}  // namespace col

/// Material id of the particles of rigid bodies (they have no material).
inline constexpr std::uint8_t kRigidMaterial = 255;
/// Material id of the node particles of rebar (rebar_elements.hpp): they carry mass, position
/// and velocity, no stress and no volume of their own (004, section 2); their elements carry
/// the material.
inline constexpr std::uint8_t kRebarNode = 254;

/// Read access to a body column of either width: u8, or u32 in models of more than 255
/// bodies (stream format 1.4). Empty when there is no column.
class BodyIds {
 public:
  BodyIds() = default;
  /// The ids of column `c` (nullptr: none); throws InputError when it is neither u8 nor u32.
  explicit BodyIds(const Column* c);
  /// The body of element i.
  int operator[](std::size_t i) const { return u8_ ? int(u8_[i]) : int(u32_[i]); }
  /// True when there is a column (even one of no rows).
  explicit operator bool() const { return present_; }

 private:
  bool present_ = false;
  const std::uint8_t* u8_ = nullptr;
  const std::uint32_t* u32_ = nullptr;
};

/// The body column a model of `bodies` bodies stores: u8 up to 255 bodies, else u32.
ColumnInfo body_column(std::size_t bodies);

/// Raw pointers into the particle columns for the kernels; optional columns are nullptr when
/// absent. Valid until the columns are resized or reordered.
template <int D>
struct ParticleView {
  std::size_t n = 0;
  Vec<D>* x = nullptr;
  Vec<D>* v = nullptr;
  double* m = nullptr;
  double* rho = nullptr;
  Sym* sigma = nullptr;
  double* e = nullptr;
  double* eps_p = nullptr;
  double* T = nullptr;
  std::uint8_t* failed = nullptr;
  double* damage = nullptr;  ///< HJC damage
  double* mu_max = nullptr;  ///< HJC largest compression
  Vec<D>* f_ext = nullptr;
  Vec<D>* f_rebar = nullptr;    ///< the rebar elements' force on their nodes (scenes with rebar)
  Vec<D>* strain = nullptr;     ///< integral of the rate of deformation's diagonal (graded grids)
  double* thickness = nullptr;  ///< thickness / initial thickness (plane stress)
  Mat<D>* C = nullptr;          ///< APIC's affine velocity (solver.scheme = "APIC")
  std::uint32_t* id = nullptr;
  std::uint8_t* material = nullptr;
  BodyIds body;
};

/// Which optional columns a scene's materials need.
struct ColumnNeeds {
  bool eps_p = false;
  bool T = false;
  bool failed = false;
  bool damage = false;  ///< HJC strength
  bool mu_max = false;  ///< HJC pressure (its unloading path)
};
ColumnNeeds column_needs(const Scene& scene);

/// Bytes of one particle in a run (the model's columns and the state columns of
/// prepare_columns), for the estimates of mpm-prep and the memory check of mpm-run.
double run_particle_bytes(const Scene& scene);

/// Bytes of one node of the dense grid window: its mass and 3 vectors of d components.
inline double grid_node_bytes(int dim) {
  return 8 + 3 * dim * 8;
}

/// Adds the state columns a run needs to a model's columns (sigma, e and the optional ones),
/// initialised to the unstressed state (T to each material's room temperature; thickness to 1
/// in plane stress; f_ext from the
/// scene's loads, shared equally among the particles each load selects), and checks the
/// model's own columns (x, v, m, rho, id, material, body) exist with the right shape.
/// Throws InputError naming the missing or malformed column, or a load that selects nothing.
void prepare_columns(ColumnStore& cols, const Scene& scene);

/// The view of a column store holding the columns of prepare_columns.
template <int D>
ParticleView<D> view(ColumnStore& cols);

}  // namespace mpm
