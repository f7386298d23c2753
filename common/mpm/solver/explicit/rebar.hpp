#pragma once
/// Rebar as truss elements (004, section 2: HFEMP; section 3.4, step 4): the nodes are
/// particles of the model (material kRebarNode) that move in the common velocity field; the
/// 2-node elements between them carry an ideal elastic-plastic axial stress and give their
/// nodes internal forces, which p2g scatters to the grid through the nodes' shape functions
/// with the particles' other forces (004, eq. 13).
///
/// Strain: engineering, eps = L / L0 - 1 from the nodes' current positions (total-strain
/// form, so that a bar stretched and released returns to its plastic length exactly); stress:
/// nominal, sigma = E (eps - eps_p), returned to +-sigma_y when it exceeds it (1D radial
/// return), axial force N = sigma A0. An element whose accumulated plastic strain passes the
/// erosion limit is removed (its nodes keep their mass, 004 section 5.3).
///
/// No races in any scatter strategy: the elements compute their forces independently, each
/// node particle then gathers its elements' forces through a fixed node -> elements list (in
/// element order, so the sums are the same bits for any thread count), and p2g scatters them
/// with the node particles by the strategy in use.
#include <cstdint>
#include <limits>
#include <vector>

#include "mpm/core/columns.hpp"
#include "mpm/core/types.hpp"
#include "mpm/scene/particles.hpp"
#include "mpm/scene/rebar_elements.hpp"
#include "mpm/scene/scene.hpp"

namespace mpm {

/// Ideal elastic-plastic axial update of one element (1D return mapping): from the total
/// strain eps and the element's plastic strain, the stress; eps_p and eps_pbar advance when
/// the trial stress exceeds sigma_y. Returns the stress (Pa).
inline double truss_stress(double eps, double E, double sigma_y, double& eps_p, double& eps_pbar) {
  const double trial = E * (eps - eps_p);
  const double excess = std::abs(trial) - sigma_y;
  if (excess <= 0) return trial;
  const double d = excess / E, sign = trial > 0 ? 1.0 : -1.0;
  eps_p += sign * d;
  eps_pbar += d;
  return sign * sigma_y;
}

/// What the element pass sums: the stored energy and the elements' stable step.
struct RebarSums {
  double energy = 0;  ///< J: A L0 (sigma^2 / 2E + sigma_y eps_pbar), elastic and plastic
  double dt_min = std::numeric_limits<double>::infinity();  ///< s: min L / (c + |v|), no cfl
  std::size_t eroded = 0;                                   ///< elements eroded so far
};

/// The rebar of a run: the element table (owned by the caller), its node lists and the
/// constants of its bars.
template <int D>
class RebarTruss {
 public:
  /// Takes the element table (rebar_elements.hpp; it stays the caller's and is updated in
  /// place) of a scene; checks it against the scene (InputError).
  void attach(ColumnStore& elements, const Scene& scene);
  bool active() const { return elements_ != nullptr; }
  /// Finds each node's particle after the particles were reordered (a sort): elements with
  /// a node that left the domain are eroded.
  void relink(const ParticleView<D>& p);
  /// Element strains from the nodes' positions, stresses, erosion, and each node's force into
  /// p.f_rebar (004, section 3.4, step 4). Parallel, deterministic.
  RebarSums update(const ParticleView<D>& p);
  /// The elements' stable step from the current positions, without updating them.
  double stable_step(const ParticleView<D>& p) const;
  std::size_t elements() const { return view_.n; }
  std::size_t bytes() const;

 private:
  ColumnStore* elements_ = nullptr;
  RebarView view_;
  struct Constants {
    double E = 0, sigma_y = 0, c = 0, eps_max = 0;
  };
  std::vector<Constants> bar_;               ///< by element: its material's and bar's constants
  std::vector<std::uint32_t> node_id_;       ///< by node slot: the particle id
  std::vector<std::uint32_t> end_;           ///< by element: its two node slots
  std::vector<std::uint32_t> first_, list_;  ///< node slot -> its elements (CSR), 2 e + end
  std::vector<std::uint32_t> index_;         ///< by node slot: the particle index (or ~0)
  std::vector<Vec<D>> force_;                ///< by element: the force on its first node, N
  std::vector<double> energy_, dt_;          ///< by element
};

}  // namespace mpm
