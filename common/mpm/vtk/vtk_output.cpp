// Implementation lands with the VTK helper; this file keeps the target non-empty meanwhile.
#include "mpm/vtk/vtk_output.hpp"
