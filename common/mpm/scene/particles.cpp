#include "mpm/scene/particles.hpp"

#include <algorithm>

#include "mpm/core/error.hpp"

namespace mpm {

ColumnNeeds column_needs(const Scene& scene) {
  ColumnNeeds need;
  for (const auto& mat : scene.materials) {
    if (mat.strength.model != StrengthModel::Elastic) need.eps_p = true;
    if (mat.strength.thermal()) need.T = true;
    if (mat.failure.enabled()) need.failed = need.eps_p = true;
    if (mat.strength.model == StrengthModel::Hjc) need.damage = true;
    if (mat.eos.model == EosModel::Hjc) need.mu_max = true;
  }
  return need;
}

namespace {
void require(const ColumnStore& cols, const std::string& name, ScalarType type, int comps) {
  const Column* c = cols.find(name);
  if (!c) throw InputError("model", "particle column '" + name + "' is missing");
  if (c->info().type != type || c->info().components != comps)
    throw InputError("model", "particle column '" + name + "' holds " +
                                  std::to_string(c->info().components) + " x " +
                                  scalar_name(c->info().type) + ", expected " +
                                  std::to_string(comps) + " x " + scalar_name(type));
}
void ensure(ColumnStore& cols, const ColumnInfo& info) {
  if (cols.find(info.name)) {
    require(cols, info.name, info.type, info.components);
    return;
  }
  cols.add(info);
}
}  // namespace

BodyIds::BodyIds(const Column* c) {
  if (!c) return;
  present_ = true;
  if (c->info().components == 1 && c->info().type == ScalarType::U8)
    u8_ = c->as<std::uint8_t>();
  else if (c->info().components == 1 && c->info().type == ScalarType::U32)
    u32_ = c->as<std::uint32_t>();
  else
    throw InputError("model", "particle column 'body' holds " +
                                  std::to_string(c->info().components) + " x " +
                                  scalar_name(c->info().type) + ", expected 1 x u8 or 1 x u32");
}

ColumnInfo body_column(std::size_t bodies) {
  return {col::body, bodies > 255 ? ScalarType::U32 : ScalarType::U8, 1, "-"};
}

void prepare_columns(ColumnStore& cols, const Scene& scene) {
  const int d = scene.dimension;
  require(cols, col::x, ScalarType::F64, d);
  require(cols, col::v, ScalarType::F64, d);
  require(cols, col::m, ScalarType::F64, 1);
  require(cols, col::rho, ScalarType::F64, 1);
  require(cols, col::id, ScalarType::U32, 1);
  require(cols, col::material, ScalarType::U8, 1);
  const auto* mat = cols.get<std::uint8_t>(col::material);
  const BodyIds body(cols.find(col::body));
  if (!body) throw InputError("model", "particle column 'body' is missing");
  for (std::size_t i = 0; i < cols.size(); ++i) {
    if (std::size_t(body[i]) >= scene.bodies.size())
      throw InputError("model", "particle " + std::to_string(i) + " refers to body " +
                                    std::to_string(body[i]) + " but the scene has " +
                                    std::to_string(scene.bodies.size()));
    if (mat[i] == kRigidMaterial && scene.bodies[body[i]].rigid) continue;
    if (mat[i] == kRebarNode && !scene.rebars.empty()) continue;
    if (mat[i] >= scene.materials.size())
      throw InputError("model", "particle " + std::to_string(i) + " refers to material " +
                                    std::to_string(mat[i]) + " but the scene has " +
                                    std::to_string(scene.materials.size()));
  }
  ensure(cols, {col::sigma, ScalarType::F64, 6, "Pa"});
  ensure(cols, {col::e, ScalarType::F64, 1, "J/kg"});
  const ColumnNeeds need = column_needs(scene);
  if (need.eps_p) ensure(cols, {col::eps_p, ScalarType::F64, 1, "-"});
  if (need.failed) ensure(cols, {col::failed, ScalarType::U8, 1, "-"});
  if (need.damage) ensure(cols, {col::damage, ScalarType::F64, 1, "-"});
  if (need.mu_max) ensure(cols, {col::mu_max, ScalarType::F64, 1, "-"});
  if (!scene.grid.levels.empty()) {
    // Graded grids: the strain that places split children (004, eq. 23) and each particle's
    // level (0 = not yet known: the level it starts in, set by the first split pass).
    ensure(cols, {col::strain, ScalarType::F64, d, "-"});
    ensure(cols, {col::level, ScalarType::U8, 1, "-"});
  }
  if (scene.solver.scheme == Scheme::APIC && !cols.has(col::C)) {
    // APIC's affine velocity: a body spinning at w starts with C = W, the skew tensor of w
    // (the exact gradient of its rigid rotation); otherwise 0 (velocity_field: first step).
    cols.add({col::C, ScalarType::F64, d * d, "1/s"});
    auto* C = reinterpret_cast<double*>(cols.at(col::C).data());
    for (std::size_t i = 0; i < cols.size(); ++i) {
      if (mat[i] == kRigidMaterial) continue;
      const Vec3& w = scene.bodies[body[i]].angular_velocity;
      double* c = C + i * d * d;  // column-major: c[a + d b] = dv_a / dx_b
      if (d == 2) {
        c[1] = w.z(), c[2] = -w.z();
      } else {
        c[1] = w.z(), c[2] = -w.y(), c[3] = -w.z(), c[5] = w.x(), c[6] = w.y(), c[7] = -w.x();
      }
    }
  }
  if (d == 2 && scene.plane_stress && !cols.has(col::thickness)) {
    cols.add({col::thickness, ScalarType::F64, 1, "-"});
    double* h = cols.get<double>(col::thickness);
    std::fill(h, h + cols.size(), 1.0);
  }
  if (need.T && !cols.has(col::T)) {
    cols.add({col::T, ScalarType::F64, 1, "K"});
    double* T = cols.get<double>(col::T);
    for (std::size_t i = 0; i < cols.size(); ++i)
      T[i] = mat[i] >= scene.materials.size() ? 0.0  // rigid particles, rebar nodes
                                              : scene.materials[mat[i]].strength.room_temperature;
  }
  if (!scene.rebars.empty()) ensure(cols, {col::f_rebar, ScalarType::F64, d, "N"});
  if (!scene.loads.empty() && !cols.has(col::f_ext)) {
    // Each load's total force, shared equally among the particles of its body whose position
    // at t = 0 lies in its region. Axisymmetric: the force is over the whole ring, the
    // particles' equations are per radian.
    cols.add({col::f_ext, ScalarType::F64, d, "N"});
    auto* f = reinterpret_cast<double*>(cols.at(col::f_ext).data());
    const auto* x = reinterpret_cast<const double*>(cols.at(col::x).data());
    const double per = 1.0 / scene.measure_factor();
    for (std::size_t l = 0; l < scene.loads.size(); ++l) {
      const LoadSpec& load = scene.loads[l];
      std::vector<std::size_t> picked;
      for (std::size_t i = 0; i < cols.size(); ++i) {
        if (body[i] != load.body) continue;
        bool in = true;
        for (int a = 0; a < d && load.region_given; ++a)
          in = in && x[i * d + a] >= load.region_min[a] && x[i * d + a] <= load.region_max[a];
        if (in) picked.push_back(i);
      }
      if (picked.empty())
        throw InputError(where(load.loc.file, load.loc.line, load.loc.key),
                         "the load selects no particle of body '" + scene.bodies[load.body].name +
                             "' (check its region against the body's particles)");
      for (auto i : picked)
        for (int a = 0; a < d; ++a) f[i * d + a] += per * load.force[a] / double(picked.size());
    }
  }
}

template <int D>
ParticleView<D> view(ColumnStore& cols) {
  ParticleView<D> p;
  p.n = cols.size();
  p.x = cols.get<Vec<D>>(col::x);
  p.v = cols.get<Vec<D>>(col::v);
  p.m = cols.get<double>(col::m);
  p.rho = cols.get<double>(col::rho);
  p.sigma = cols.get<Sym>(col::sigma);
  p.e = cols.get<double>(col::e);
  p.eps_p = cols.get<double>(col::eps_p);
  p.T = cols.get<double>(col::T);
  p.failed = cols.get<std::uint8_t>(col::failed);
  p.damage = cols.get<double>(col::damage);
  p.mu_max = cols.get<double>(col::mu_max);
  p.f_ext = cols.get<Vec<D>>(col::f_ext);
  p.f_rebar = cols.get<Vec<D>>(col::f_rebar);
  p.strain = cols.get<Vec<D>>(col::strain);
  p.thickness = cols.get<double>(col::thickness);
  p.C = cols.get<Mat<D>>(col::C);
  p.id = cols.get<std::uint32_t>(col::id);
  p.material = cols.get<std::uint8_t>(col::material);
  p.body = BodyIds(cols.find(col::body));
  return p;
}
template ParticleView<2> view<2>(ColumnStore&);
template ParticleView<3> view<3>(ColumnStore&);

double run_particle_bytes(const Scene& scene) {
  const ColumnNeeds need = column_needs(scene);
  const int d = scene.dimension;
  // x and v, m, rho and e, sigma, id, material and body, then the optional columns.
  return 2 * d * 8 + 3 * 8 + 48 + 4 + 1 + 1 + (need.eps_p ? 8 : 0) + (need.T ? 8 : 0) +
         (need.failed ? 1 : 0) + (need.damage ? 8 : 0) + (need.mu_max ? 8 : 0) +
         (d == 2 && scene.plane_stress ? 8 : 0) + (scene.rebars.empty() ? 0 : d * 8) +
         (scene.solver.scheme == Scheme::APIC ? d * d * 8 : 0);
}

}  // namespace mpm
