#pragma once
/// The rebar's truss elements (004, section 2: HFEMP) as named columns, one element a row:
/// what mpm-prep writes in the model's REBR record, mpm-run advances and writes with each frame,
/// and mpm-post draws. The nodes are particles of the model (material kRebarNode): they carry
/// the lumped mass, position and velocity; the elements carry the material.
#include <cstdint>
#include <string>

#include "mpm/core/columns.hpp"
#include "mpm/scene/particles.hpp"
#include "mpm/scene/scene.hpp"

namespace mpm {

/// Element column names.
namespace rebar_col {
inline const std::string nodes = "nodes";        ///< 2 x u32: the node particles' ids
inline const std::string bar = "bar";            ///< u32: index into Scene::rebars
inline const std::string material = "material";  ///< u8: index into Scene::materials
inline const std::string area = "area";          ///< f64: section, m^2
inline const std::string length0 = "length0";    ///< f64: rest length, m
inline const std::string sigma = "sigma";        ///< f64: axial stress (nominal), Pa
inline const std::string eps_p = "eps_p";        ///< f64: axial plastic strain (signed), -
inline const std::string eps_pbar = "eps_pbar";  ///< f64: accumulated plastic strain, -
inline const std::string eroded = "eroded";      ///< u8: 1 once eps_pbar passed the limit
}  // namespace rebar_col

/// An element table with the columns above and no rows.
ColumnStore rebar_element_columns();

/// Raw pointers into an element table (valid until it is resized).
struct RebarView {
  std::size_t n = 0;
  const std::uint32_t* nodes = nullptr;  ///< 2 per element
  const std::uint32_t* bar = nullptr;
  const std::uint8_t* material = nullptr;
  const double* area = nullptr;
  const double* length0 = nullptr;
  double* sigma = nullptr;
  double* eps_p = nullptr;
  double* eps_pbar = nullptr;
  std::uint8_t* eroded = nullptr;
};
/// The view of an element table; throws InputError naming a missing or malformed column, an
/// element whose bar or material the scene does not have, or a non-positive area or length.
RebarView rebar_view(ColumnStore& elements, const Scene& scene);

}  // namespace mpm
