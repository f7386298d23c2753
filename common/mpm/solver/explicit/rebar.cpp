// Rebar truss elements (rebar.hpp): their node lists, the element pass and the node gather.
#include "mpm/solver/explicit/rebar.hpp"

#include <omp.h>

#include <algorithm>
#include <cmath>

#include "mpm/core/error.hpp"

namespace mpm {

namespace {
constexpr long kParallelFrom = 8192;  ///< elements or nodes below which a pass runs serially
}  // namespace

template <int D>
void RebarTruss<D>::attach(ColumnStore& elements, const Scene& scene) {
  elements_ = &elements;
  view_ = rebar_view(elements, scene);
  const std::size_t ne = view_.n;
  // Constants by element: E and sigma_y of its material, c = sqrt(E / rho), its bar's limit.
  bar_.resize(ne);
  for (std::size_t e = 0; e < ne; ++e) {
    const MaterialSpec& m = scene.materials[view_.material[e]];
    Constants& k = bar_[e];
    k.E = m.youngs_modulus;
    k.sigma_y = m.strength.model == StrengthModel::Elastic ? std::numeric_limits<double>::infinity()
                                                           : m.strength.A;
    k.c = std::sqrt(m.youngs_modulus / m.density);
    k.eps_max = scene.rebars[view_.bar[e]].erosion_strain;
    if (!(k.E > 0) || !(m.density > 0))
      throw InputError(where(m.loc.file, m.loc.line, "materials." + m.name),
                       "rebar needs a material with a positive density and youngs_modulus");
  }
  // Node slots: the distinct node ids, sorted; each element's two slots.
  node_id_.assign(view_.nodes, view_.nodes + 2 * ne);
  std::sort(node_id_.begin(), node_id_.end());
  node_id_.erase(std::unique(node_id_.begin(), node_id_.end()), node_id_.end());
  end_.resize(2 * ne);
  for (std::size_t j = 0; j < 2 * ne; ++j)
    end_[j] = std::uint32_t(std::lower_bound(node_id_.begin(), node_id_.end(), view_.nodes[j]) -
                            node_id_.begin());
  // Node -> elements (CSR, in element order): entry 2 e + j, the element's end j.
  first_.assign(node_id_.size() + 1, 0);
  for (std::size_t j = 0; j < 2 * ne; ++j) ++first_[end_[j] + 1];
  for (std::size_t k = 0; k < node_id_.size(); ++k) first_[k + 1] += first_[k];
  list_.resize(2 * ne);
  std::vector<std::uint32_t> fill(first_.begin(), first_.end() - 1);
  for (std::size_t j = 0; j < 2 * ne; ++j) list_[fill[end_[j]]++] = std::uint32_t(j);
  index_.assign(node_id_.size(), ~0u);
  force_.assign(ne, Vec<D>::Zero());
  energy_.assign(ne, 0.0);
  dt_.assign(ne, std::numeric_limits<double>::infinity());
}

template <int D>
void RebarTruss<D>::relink(const ParticleView<D>& p) {
  std::fill(index_.begin(), index_.end(), ~0u);
  if (node_id_.empty()) return;
  const std::uint32_t lo = node_id_.front(), hi = node_id_.back();
#pragma omp parallel for schedule(static)
  for (std::size_t i = 0; i < p.n; ++i) {
    if (p.material[i] != kRebarNode || p.id[i] < lo || p.id[i] > hi) continue;
    const auto it = std::lower_bound(node_id_.begin(), node_id_.end(), p.id[i]);
    if (it != node_id_.end() && *it == p.id[i]) index_[it - node_id_.begin()] = std::uint32_t(i);
  }
  // A node that left the domain (removed at the sort) takes its elements with it.
  for (std::size_t e = 0; e < view_.n; ++e)
    if (index_[end_[2 * e]] == ~0u || index_[end_[2 * e + 1]] == ~0u) view_.eroded[e] = 1;
}

template <int D>
RebarSums RebarTruss<D>::update(const ParticleView<D>& p) {
  const long ne = long(view_.n);
  RebarView& el = view_;
  // Elements: strain from the nodes' positions, stress by return mapping, erosion, force.
  // (Threads only for many elements: a parallel region costs more than a few thousand.)
#pragma omp parallel for schedule(static) if (ne > kParallelFrom)
  for (long e = 0; e < ne; ++e) {
    const Constants& k = bar_[e];
    if (el.eroded[e]) {  // what its plastic work dissipated stays booked
      force_[e].setZero();
      const double plastic = std::isfinite(k.sigma_y) ? k.sigma_y * el.eps_pbar[e] : 0.0;
      energy_[e] = el.area[e] * el.length0[e] * plastic;
      dt_[e] = std::numeric_limits<double>::infinity();
      continue;
    }
    const std::uint32_t a = index_[end_[2 * e]], b = index_[end_[2 * e + 1]];
    const Vec<D> dx = p.x[b] - p.x[a];
    const double L = dx.norm(), L0 = el.length0[e];
    const double eps = L / L0 - 1;  // engineering strain
    double sigma = truss_stress(eps, k.E, k.sigma_y, el.eps_p[e], el.eps_pbar[e]);
    if (el.eps_pbar[e] > k.eps_max) el.eroded[e] = 1, sigma = 0;  // (004, section 5.3)
    el.sigma[e] = sigma;
    force_[e] = L > 0 ? Vec<D>((sigma * el.area[e] / L) * dx) : Vec<D>::Zero();
    const double plastic = std::isfinite(k.sigma_y) ? k.sigma_y * el.eps_pbar[e] : 0.0;
    energy_[e] = el.area[e] * L0 * (0.5 * sigma * sigma / k.E + plastic);  // stored, dissipated
    dt_[e] = L / (k.c + std::max(p.v[a].norm(), p.v[b].norm()));
  }
  // Nodes: each gathers its elements' forces, in element order (004, eq. 13's f_r^int).
  const long nn = long(node_id_.size());
#pragma omp parallel for schedule(static) if (nn > kParallelFrom)
  for (long k = 0; k < nn; ++k) {
    if (index_[k] == ~0u) continue;
    Vec<D> f = Vec<D>::Zero();
    for (std::uint32_t j = first_[k]; j < first_[k + 1]; ++j) {
      const std::uint32_t entry = list_[j];
      const Vec<D>& F = force_[entry / 2];
      if (entry % 2 == 0)
        f += F;  // a tensile element pulls its first node towards its second
      else
        f -= F;
    }
    p.f_rebar[index_[k]] = f;
  }
  RebarSums s;
  for (long e = 0; e < ne; ++e) {
    s.energy += energy_[e];
    s.dt_min = std::min(s.dt_min, dt_[e]);
    s.eroded += el.eroded[e];
  }
  return s;
}

template <int D>
double RebarTruss<D>::stable_step(const ParticleView<D>& p) const {
  double dt = std::numeric_limits<double>::infinity();
  for (std::size_t e = 0; e < view_.n; ++e) {
    const std::uint32_t a = index_[end_[2 * e]], b = index_[end_[2 * e + 1]];
    if (view_.eroded[e] || a == ~0u || b == ~0u) continue;
    const double L = (p.x[b] - p.x[a]).norm();
    dt = std::min(dt, L / (bar_[e].c + std::max(p.v[a].norm(), p.v[b].norm())));
  }
  return dt;
}

template <int D>
std::size_t RebarTruss<D>::bytes() const {
  return bar_.capacity() * sizeof(Constants) +
         (node_id_.capacity() + end_.capacity() + first_.capacity() + list_.capacity() +
          index_.capacity()) *
             4 +
         force_.capacity() * sizeof(Vec<D>) + (energy_.capacity() + dt_.capacity()) * 8;
}

template class RebarTruss<2>;
template class RebarTruss<3>;

}  // namespace mpm
