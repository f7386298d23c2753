// Triangle-mesh bodies: reading, checking and inside tests with CGAL (the only translation
// unit that includes CGAL; it compiles slowly).
#include "mpm/prep/mesh_region.hpp"

#include <CGAL/AABB_face_graph_triangle_primitive.h>
#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/IO/polygon_soup_io.h>
#include <CGAL/Polygon_mesh_processing/measure.h>
#include <CGAL/Polygon_mesh_processing/orient_polygon_soup.h>
#include <CGAL/Polygon_mesh_processing/orientation.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Polygon_mesh_processing/repair_polygon_soup.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Polygon_mesh_processing/shape_predicates.h>
#include <CGAL/Polygon_mesh_processing/triangulate_hole.h>
#include <CGAL/Side_of_triangle_mesh.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/boost/graph/helpers.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <exception>
#include <filesystem>
#include <optional>
#include <unordered_map>
#include <vector>

#include "mpm/core/error.hpp"
#include "mpm/core/units.hpp"
#include "mpm/prep/body_placement.hpp"
#include "mpm/prep/mesh_file_checks.hpp"

// Several OpenMP threads query one AABB tree. CGAL guards its lazily built structures only
// when it knows threads exist; without CGAL_HAS_THREADS it may use unguarded statics.
#ifndef CGAL_HAS_THREADS
#error "CGAL must be compiled with thread support (CGAL_HAS_THREADS) for the parallel voxeliser"
#endif

namespace mpm {

namespace {

namespace PMP = CGAL::Polygon_mesh_processing;
using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = K::Point_3;
using Mesh = CGAL::Surface_mesh<Point>;
using Primitive = CGAL::AABB_face_graph_triangle_primitive<Mesh>;
using Tree = CGAL::AABB_tree<CGAL::AABB_traits<K, Primitive>>;
using Side = CGAL::Side_of_triangle_mesh<Mesh, K, CGAL::Default, Tree>;

/// Faces of more than three vertices (quads from exporters) as triangles, each polygon by
/// CGAL's hole-filling triangulation of its outline (dynamic programming over its vertices: it
/// always ends, where triangulate_faces on the halfedge mesh looped on a fuzzed OBJ, see
/// tests/fuzz/README.md). A polygon it cannot split into n - 2 triangles is refused by number.
void triangulate_polygons(const std::vector<Point>& points,
                          std::vector<std::vector<std::size_t>>& polygons, const std::string& at,
                          const std::string& name) {
  std::vector<std::vector<std::size_t>> out;
  out.reserve(polygons.size());
  for (std::size_t f = 0; f < polygons.size(); ++f) {
    const auto& poly = polygons[f];
    if (poly.size() == 3) {
      out.push_back(poly);
      continue;
    }
    std::vector<Point> outline;
    for (std::size_t i : poly) outline.push_back(points[i]);
    std::vector<CGAL::Triple<int, int, int>> tris;
    PMP::triangulate_hole_polyline(outline, std::back_inserter(tris));
    if (tris.size() != poly.size() - 2)
      throw InputError(at, "mesh " + name + ": face " + std::to_string(f + 1) + " (" +
                               std::to_string(poly.size()) +
                               " vertices) cannot be split into triangles; split it in the "
                               "file or export triangles");
    for (const auto& t : tris)
      out.push_back(
          {poly[std::size_t(t.first)], poly[std::size_t(t.second)], poly[std::size_t(t.third)]});
  }
  polygons.swap(out);
}

/// Vertices this close (a fraction of the mesh's bounding-box diagonal, in each coordinate) are
/// one vertex: exporters and unit conversions leave shared vertices a hair apart (an STL with
/// vertices 1e-18 m apart read as "not closed"). 1e-7 is float32's resolution, the precision of
/// binary STL, and far below any particle spacing.
constexpr double kWeldTolerance = 1e-7;

/// Moves each vertex within `tol` (in every coordinate) of an earlier one onto it, so that the
/// soup repair merges them; returns how many moved. A hash of cells of side tol, searched in
/// the 27 around each vertex.
std::size_t weld_vertices(std::vector<Point>& points, double tol) {
  if (points.empty() || !(tol > 0)) return 0;
  double lo[3] = {points[0].x(), points[0].y(), points[0].z()};
  for (const Point& p : points)
    for (int a = 0; a < 3; ++a) lo[a] = std::min(lo[a], p[a]);
  auto cell = [&](const Point& p, int a) { return std::int64_t(std::floor((p[a] - lo[a]) / tol)); };
  auto key = [](std::int64_t i, std::int64_t j, std::int64_t k) {
    return (std::uint64_t(i) * 73856093u) ^ (std::uint64_t(j) * 19349663u) ^
           (std::uint64_t(k) * 83492791u);
  };
  std::unordered_multimap<std::uint64_t, std::size_t> cells;
  std::size_t moved = 0;
  for (std::size_t n = 0; n < points.size(); ++n) {
    const std::int64_t c[3] = {cell(points[n], 0), cell(points[n], 1), cell(points[n], 2)};
    std::optional<std::size_t> hit;
    for (int d = 0; d < 27 && !hit; ++d) {
      const auto range =
          cells.equal_range(key(c[0] + d % 3 - 1, c[1] + d / 3 % 3 - 1, c[2] + d / 9 - 1));
      for (auto it = range.first; it != range.second && !hit; ++it) {
        const Point& q = points[it->second];
        if (std::abs(q.x() - points[n].x()) <= tol && std::abs(q.y() - points[n].y()) <= tol &&
            std::abs(q.z() - points[n].z()) <= tol)
          hit = it->second;
      }
    }
    if (hit) {
      if (points[n] != points[*hit]) ++moved;
      points[n] = points[*hit];
    } else {
      cells.emplace(key(c[0], c[1], c[2]), n);
    }
  }
  return moved;
}

std::string lower_extension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

/// Reads a body's mesh file into a triangle mesh placed in the world (vertices transformed).
/// Refuses missing, unreadable, empty and non-manifold files; closedness is checked later.
Mesh read_placed_mesh(const BodySpec& body, const Scene& scene) {
  const std::string at = body_where(scene, body, "file");
  const std::string name = "'" + body.mesh_path + "'";
  if (scene.dimension == 2)
    throw InputError(body_where(scene, body, "shape"),
                     "body '" + body.name + "' is a mesh; a 2D scene takes only box and sphere");
  if (body.mesh_path.empty())
    throw InputError(at, "body '" + body.name + "' has shape mesh but no file");
  const std::string path = resolve_mesh_path(body, scene);
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec))
    throw InputError(at, "cannot read mesh " + name + ": no such file" +
                             (path == body.mesh_path ? "" : " (looked for '" + path + "')"));
  const std::string ext = lower_extension(path);
  if (ext != ".stl" && ext != ".off" && ext != ".obj")
    throw InputError(at, "cannot read mesh " + name + ": unknown format '" + ext +
                             "'; use .stl (ASCII or binary), .off or .obj");

  std::vector<Point> points;
  std::vector<std::vector<std::size_t>> polygons;
  if (ext == ".off") check_off_faces(path, at, name);
  bool ok = false;
  try {
    ok = CGAL::IO::read_polygon_soup(path, points, polygons, CGAL::parameters::verbose(false));
  } catch (const std::exception& e) {
    throw InputError(at, "cannot read mesh " + name + ": " + e.what());
  }
  std::string format = ext.substr(1);
  std::transform(format.begin(), format.end(), format.begin(),
                 [](unsigned char c) { return static_cast<char>(std::toupper(c)); });
  if (!ok)
    throw InputError(at, "cannot read mesh " + name + ": not a valid " + format + " file" +
                             (points.empty() ? " (no vertices found)" : ""));
  for (const auto& poly : polygons)
    for (std::size_t i : poly)
      if (i >= points.size())
        throw InputError(at, "cannot read mesh " + name + ": a face refers to vertex " +
                                 std::to_string(i) + " of " + std::to_string(points.size()));
  for (const Point& p : points)
    if (!std::isfinite(p.x()) || !std::isfinite(p.y()) || !std::isfinite(p.z()))
      throw InputError(at, "mesh " + name + " has a vertex that is not a finite number");

  {
    CGAL::Bbox_3 box;
    for (const Point& p : points) box += p.bbox();
    const double diagonal =
        std::sqrt(CGAL::square(box.xmax() - box.xmin()) + CGAL::square(box.ymax() - box.ymin()) +
                  CGAL::square(box.zmax() - box.zmin()));
    weld_vertices(points, kWeldTolerance * diagonal);
  }
  Mesh mesh;
  try {
    // Merge duplicate vertices (STL repeats them per triangle), drop degenerate polygons,
    // orient the faces consistently, then build the halfedge structure.
    PMP::repair_polygon_soup(points, polygons);
    if (polygons.empty())
      throw InputError(at, "mesh " + name + " is empty: it has no (non-degenerate) faces");
    triangulate_polygons(points, polygons, at, name);
    PMP::orient_polygon_soup(points, polygons);
    if (!PMP::is_polygon_soup_a_polygon_mesh(polygons))
      throw InputError(at, "mesh " + name +
                               " is not a manifold surface (an edge is shared by more than two "
                               "faces); repair it or use a primitive");
    PMP::polygon_soup_to_polygon_mesh(points, polygons, mesh);
  } catch (const InputError&) {
    throw;
  } catch (const std::exception& e) {
    throw InputError(at, "cannot read mesh " + name + ": " + e.what());
  }
  if (mesh.number_of_faces() == 0)
    throw InputError(at, "mesh " + name + " is empty: it has no faces");

  // Place it: scale, rotate, translate.
  const Mat3 A = body_linear_map(body);
  const Vec3 t = body.translate;
  for (auto v : mesh.vertices()) {
    const Point& p = mesh.point(v);
    const Vec3 w = A * Vec3(p.x(), p.y(), p.z()) + t;
    mesh.point(v) = Point(w.x(), w.y(), w.z());
  }
  return mesh;
}

void mesh_box(const Mesh& mesh, Vec3& lo, Vec3& hi) {
  lo = Vec3::Constant(std::numeric_limits<double>::infinity());
  hi = -lo;
  for (auto v : mesh.vertices()) {
    const Point& p = mesh.point(v);
    const Vec3 x(p.x(), p.y(), p.z());
    lo = lo.cwiseMin(x);
    hi = hi.cwiseMax(x);
  }
}

/// "4 border edges around 1 hole: 4 edges around (x, y, z) ... in the file's coordinates":
/// the holes of a mesh (cycles of border edges), each by its edge count and the centre of its
/// vertices in the file's coordinates (the placement undone), the first three of them; empty
/// when the mesh is closed.
std::string describe_holes(const Mesh& mesh, const BodySpec& body) {
  std::size_t border = 0;
  for (auto h : mesh.halfedges())
    if (mesh.is_border(h)) ++border;
  if (border == 0) return "";
  const Mat3 A = body_linear_map(body);
  const bool invertible = std::abs(A.determinant()) > 0;
  std::vector<bool> seen(mesh.number_of_halfedges(), false);
  std::size_t holes = 0;
  std::string where;
  for (auto h : mesh.halfedges()) {
    if (!mesh.is_border(h) || seen[h.idx()]) continue;
    ++holes;
    Vec3 c = Vec3::Zero();
    std::size_t edges = 0;
    // Along the border by next(), stopping at an edge already walked: a hole's cycle need
    // not come back to h on a mesh the soup repair left odd (a loop that never did was found
    // by fuzz_mesh), so each border edge is walked once at most.
    for (auto g = h; mesh.is_border(g) && !seen[g.idx()]; g = mesh.next(g)) {
      seen[g.idx()] = true;
      const Point& p = mesh.point(mesh.target(g));
      c += Vec3(p.x(), p.y(), p.z());
      ++edges;
    }
    c /= double(edges);
    if (invertible) c = A.inverse() * (c - body.translate);
    if (holes <= 3)
      where += std::string(holes > 1 ? "; " : "") + std::to_string(edges) + " edges around (" +
               format_g6(c.x()) + ", " + format_g6(c.y()) + ", " + format_g6(c.z()) + ")";
  }
  return std::to_string(border) + " border edges around " + std::to_string(holes) +
         (holes == 1 ? " hole: " : " holes: ") + where + (holes > 3 ? "; ..." : "") +
         " in the file's coordinates";
}

}  // namespace

struct MeshRegion::Impl {
  Mesh mesh;
  Tree tree;
  std::optional<Side> side;
  double volume = 0;
  Vec3 lo, hi;
};

MeshRegion::MeshRegion(const BodySpec& body, const Scene& scene) : impl_(std::make_unique<Impl>()) {
  const std::string at = body_where(scene, body, "file");
  const std::string name = "'" + body.mesh_path + "'";
  Mesh& mesh = impl_->mesh;
  mesh = read_placed_mesh(body, scene);

  if (const std::string holes = describe_holes(mesh, body); !holes.empty())
    throw InputError(at,
                     "mesh " + name + " is not closed: " + holes + "; close it or use a primitive");
  std::size_t degenerate = 0;
  for (auto f : mesh.faces())
    if (PMP::is_degenerate_triangle_face(f, mesh)) ++degenerate;
  if (degenerate > 0)
    throw InputError(at, "mesh " + name + " has " + std::to_string(degenerate) +
                             " degenerate (zero-area) triangles; repair it or use a primitive");
  if (PMP::does_self_intersect(mesh))
    throw InputError(at, "mesh " + name +
                             " intersects itself, so its inside is ambiguous; repair it (merge "
                             "overlapping parts) or use a primitive");
  // Closed, manifold and free of self-intersections: orient every component so that the
  // signed volume counts nested shells correctly (a hollow part subtracts).
  PMP::orient_to_bound_a_volume(mesh);
  impl_->volume = std::abs(PMP::volume(mesh));
  mesh_box(mesh, impl_->lo, impl_->hi);

  // Build the tree before any query: after build() every query only reads it, so
  // Side_of_triangle_mesh::operator() const (given a built tree, it never builds lazily) and
  // AABB_tree::do_intersect are safe from several OpenMP threads.
  impl_->tree.insert(faces(mesh).first, faces(mesh).second, mesh);
  impl_->tree.build();
  impl_->side.emplace(impl_->tree);
}

MeshRegion::~MeshRegion() = default;

bool MeshRegion::contains(const Vec3& x) const {
  if ((x.array() < impl_->lo.array()).any() || (x.array() > impl_->hi.array()).any()) return false;
  return (*impl_->side)(Point(x.x(), x.y(), x.z())) == CGAL::ON_BOUNDED_SIDE;
}

double MeshRegion::volume() const {
  return impl_->volume;
}

void MeshRegion::bounds(Vec3& lo, Vec3& hi) const {
  lo = impl_->lo;
  hi = impl_->hi;
}

int MeshRegion::classify_box(const Vec3& lo, const Vec3& hi) const {
  if ((hi.array() < impl_->lo.array()).any() || (lo.array() > impl_->hi.array()).any()) return 0;
  const K::Iso_cuboid_3 box(Point(lo.x(), lo.y(), lo.z()), Point(hi.x(), hi.y(), hi.z()));
  if (impl_->tree.do_intersect(box)) return -1;
  // The surface misses the (connected) box: every point of it is on the side of its centre.
  const Vec3 c = 0.5 * (lo + hi);
  return (*impl_->side)(Point(c.x(), c.y(), c.z())) == CGAL::ON_BOUNDED_SIDE ? 1 : 0;
}

std::size_t MeshRegion::triangles() const {
  return impl_->mesh.number_of_faces();
}

void mesh_body_bounds(const BodySpec& body, const Scene& scene, Vec3& lo, Vec3& hi) {
  mesh_box(read_placed_mesh(body, scene), lo, hi);
}

}  // namespace mpm
