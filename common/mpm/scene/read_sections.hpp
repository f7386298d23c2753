#pragma once
/// Private to the scene parser (scene/*.cpp): the readers of the scene file's sections, each
/// filling its part of the Scene from the top-level Reader (toml_reader.hpp).
#include "mpm/scene/scene.hpp"
#include "mpm/scene/toml_reader.hpp"

namespace mpm::scene_toml {

/// [materials.<name>]: one MaterialSpec per table, in alphabetical order (read_materials.cpp).
void read_materials(Reader& top, Scene& s);
/// [[bodies]]: names, shapes, placement, particles (read_bodies.cpp).
void read_bodies(Reader& top, Scene& s);
/// [[loads]]: forces on bodies (read_bodies.cpp).
void read_loads(Reader& top, Scene& s);
/// [[contact]]: body pairs with their own velocity fields (read_bodies.cpp).
void read_contacts(Reader& top, Scene& s);
/// [[rebar]]: bars, layers and polyline files of truss elements (read_rebar.cpp).
void read_rebars(Reader& top, Scene& s);
/// [grid] with its domain and [[grid.levels]] (read_grid.cpp).
void read_grid(Reader& r, Scene& s);
/// A body's own particle spacing against the grid (bodies are read before [grid]).
void check_particle_spacing(const Scene& s);
/// [boundary]: the type of each domain face (read_grid.cpp).
void read_boundary(Reader& r, Scene& s);
/// [solver] with [solver.implicit] (read_solver.cpp).
void read_solver(Reader& r, Scene& s);
/// [output] (read_solver.cpp).
void read_output(Reader& r, Scene& s);

}  // namespace mpm::scene_toml
