#include "mpm/scene/rebar_elements.hpp"

#include "mpm/core/error.hpp"

namespace mpm {

ColumnStore rebar_element_columns() {
  ColumnStore e;
  e.add({rebar_col::nodes, ScalarType::U32, 2, "-"});
  e.add({rebar_col::bar, ScalarType::U32, 1, "-"});
  e.add({rebar_col::material, ScalarType::U8, 1, "-"});
  e.add({rebar_col::area, ScalarType::F64, 1, "m^2"});
  e.add({rebar_col::length0, ScalarType::F64, 1, "m"});
  e.add({rebar_col::sigma, ScalarType::F64, 1, "Pa"});
  e.add({rebar_col::eps_p, ScalarType::F64, 1, "-"});
  e.add({rebar_col::eps_pbar, ScalarType::F64, 1, "-"});
  e.add({rebar_col::eroded, ScalarType::U8, 1, "-"});
  return e;
}

namespace {
template <class T>
T* column(ColumnStore& e, const std::string& name, ScalarType type, int comps) {
  Column* c = e.find(name);
  if (!c) throw InputError("model", "rebar element column '" + name + "' is missing");
  if (c->info().type != type || c->info().components != comps)
    throw InputError("model", "rebar element column '" + name + "' holds " +
                                  std::to_string(c->info().components) + " x " +
                                  scalar_name(c->info().type) + ", expected " +
                                  std::to_string(comps) + " x " + scalar_name(type));
  return reinterpret_cast<T*>(c->data());  // checked above: comps x the type
}
}  // namespace

RebarView rebar_view(ColumnStore& e, const Scene& scene) {
  RebarView v;
  v.n = e.size();
  v.nodes = column<std::uint32_t>(e, rebar_col::nodes, ScalarType::U32, 2);
  v.bar = column<std::uint32_t>(e, rebar_col::bar, ScalarType::U32, 1);
  v.material = column<std::uint8_t>(e, rebar_col::material, ScalarType::U8, 1);
  v.area = column<double>(e, rebar_col::area, ScalarType::F64, 1);
  v.length0 = column<double>(e, rebar_col::length0, ScalarType::F64, 1);
  v.sigma = column<double>(e, rebar_col::sigma, ScalarType::F64, 1);
  v.eps_p = column<double>(e, rebar_col::eps_p, ScalarType::F64, 1);
  v.eps_pbar = column<double>(e, rebar_col::eps_pbar, ScalarType::F64, 1);
  v.eroded = column<std::uint8_t>(e, rebar_col::eroded, ScalarType::U8, 1);
  for (std::size_t k = 0; k < v.n; ++k) {
    const std::string el = "rebar element " + std::to_string(k);
    if (v.bar[k] >= scene.rebars.size())
      throw InputError("model", el + " refers to [[rebar]] entry " + std::to_string(v.bar[k]) +
                                    " but the scene has " + std::to_string(scene.rebars.size()));
    if (v.material[k] >= scene.materials.size())
      throw InputError("model", el + " refers to material " + std::to_string(v.material[k]) +
                                    " but the scene has " + std::to_string(scene.materials.size()));
    if (!(v.area[k] > 0) || !(v.length0[k] > 0))
      throw InputError("model", el + " has a non-positive area or rest length");
  }
  return v;
}

}  // namespace mpm
