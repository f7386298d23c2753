#pragma once
/// Private to prep (mesh_region.cpp): checks of mesh files made before CGAL reads them, for
/// what CGAL's readers do not survive cleanly (their behaviour is undefined, or they loop).
#include <string>

namespace mpm {

/// An ASCII OFF file's faces: each face line must start with its vertex count and list that
/// many vertex indices, all whole numbers from 0 (CGAL converts them from double unchecked:
/// "-1" or "1e30" is undefined behaviour there), and only plain OFF is read (CGAL reads the
/// entries of the texture, colour and normal variants unchecked). Binary OFF is left to CGAL.
/// Throws InputError(at, ...) naming the mesh `name` and the line.
void check_off_faces(const std::string& path, const std::string& at, const std::string& name);

}  // namespace mpm
