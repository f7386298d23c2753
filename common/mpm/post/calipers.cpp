#include "mpm/post/calipers.hpp"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/convex_hull_2.h>

#include <algorithm>
#include <cmath>
#include <iterator>
#include <numbers>

namespace mpm {

Calipers caliper_widths(const std::vector<double>& x, const std::vector<double>& y) {
  using K = CGAL::Exact_predicates_inexact_constructions_kernel;
  using P = K::Point_2;
  Calipers c;
  const std::size_t n = std::min(x.size(), y.size());
  if (n == 0) return c;
  std::vector<P> points;
  points.reserve(n);
  for (std::size_t i = 0; i < n; ++i) points.emplace_back(x[i], y[i]);
  std::vector<P> hull;
  CGAL::convex_hull_2(points.begin(), points.end(), std::back_inserter(hull));
  const std::size_t h = hull.size();
  c.hull_vertices = h;
  if (h < 2) return c;
  auto dist = [](const P& a, const P& b) { return std::hypot(a.x() - b.x(), a.y() - b.y()); };
  // Cauchy's formula: the mean width of a convex set is its perimeter over pi (a segment's
  // "perimeter" is twice its length, both ways round, which the loop gives for h = 2).
  double perimeter = 0;
  for (std::size_t i = 0; i < h; ++i) perimeter += dist(hull[i], hull[(i + 1) % h]);
  c.mean = perimeter / std::numbers::pi;
  // Widest: the largest distance between two hull vertices.
  for (std::size_t i = 0; i < h; ++i)
    for (std::size_t j = i + 1; j < h; ++j) c.max = std::max(c.max, dist(hull[i], hull[j]));
  if (h == 2) return c;  // a segment: no width across it
  // Narrowest: attained across an edge of the hull; for each edge, the farthest vertex.
  c.min = c.max;
  for (std::size_t i = 0; i < h; ++i) {
    const P& a = hull[i];
    const P& b = hull[(i + 1) % h];
    const double ex = b.x() - a.x(), ey = b.y() - a.y(), len = std::hypot(ex, ey);
    if (!(len > 0)) continue;
    double far = 0;
    for (std::size_t j = 0; j < h; ++j)
      far = std::max(far, std::abs(ex * (hull[j].y() - a.y()) - ey * (hull[j].x() - a.x())) / len);
    c.min = std::min(c.min, far);
  }
  return c;
}

}  // namespace mpm
