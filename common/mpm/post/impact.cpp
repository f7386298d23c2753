// The impact the measures look at: projectile, target, axis, and where the target stood.
#include "mpm/post/impact.hpp"

#include <algorithm>
#include <cmath>

#include "mpm/core/error.hpp"
#include "mpm/scene/particles.hpp"

namespace mpm {

Impact find_impact(const Scene& scene, const Frame& first, const Symmetry& symmetry,
                   const ImpactChoice& choice, const std::string& command) {
  const Column* xc = first.columns.find(col::x);
  const Column* bc = first.columns.find(col::body);
  if (!xc || !bc) throw InputError(command, "frames need the columns 'x' and 'body'");
  Impact im;
  im.dimension = xc->info().components;
  const int nb = int(scene.bodies.size());
  auto find = [&](const std::string& name, const char* option) {
    const int b = scene.body_index(name);
    if (b < 0) throw InputError(option, "no body named '" + name + "' in the scene");
    return b;
  };
  // Projectile: the fastest body; target: the first body at rest.
  im.projectile = choice.projectile.empty() ? -1 : find(choice.projectile, "--projectile");
  im.target = choice.target.empty() ? -1 : find(choice.target, "--target");
  if (im.projectile < 0) {
    double best = 0;
    for (int b = 0; b < nb; ++b)
      if (b != im.target && scene.bodies[b].velocity.norm() > best)
        best = scene.bodies[b].velocity.norm(), im.projectile = b;
    if (im.projectile < 0) throw InputError(command, "no body moves at t = 0: give --projectile");
  }
  if (im.target < 0) {
    for (int b = 0; b < nb && im.target < 0; ++b)
      if (b != im.projectile && scene.bodies[b].velocity.norm() == 0) im.target = b;
    if (im.target < 0) throw InputError(command, "no body is at rest at t = 0: give --target");
  }
  const Vec3 vp = scene.bodies[im.projectile].velocity;
  im.axis = choice.axis;
  if (scene.axisymmetric && im.axis >= 0 && im.axis != 1)
    throw InputError(
        "--axis",
        "an axisymmetric scene's impact axis is its axis of revolution y (x is the radius)");
  if (scene.axisymmetric) im.axis = 1;
  if (im.axis < 0) {
    im.axis = 0;
    for (int a = 1; a < im.dimension; ++a)
      if (std::abs(vp[a]) > std::abs(vp[im.axis])) im.axis = a;
  }
  im.direction = vp[im.axis] < 0 ? -1 : 1;
  // The whole projectile's initial centre, and the whole target's faces (particle centres).
  const WholeBody projectile = unfold(first, im.dimension, symmetry, {im.projectile});
  const WholeBody target = unfold(first, im.dimension, symmetry, {im.target});
  if (projectile.x.empty() || target.x.empty())
    throw InputError(command, "the first frame lacks the projectile or the target");
  for (const Vec3& p : projectile.x) im.point += p;
  im.point /= double(projectile.x.size());
  if (scene.axisymmetric) im.point.x() = 0;  // the axis of revolution, whatever the rings
  im.front = 1e300, im.rear = -1e300;
  for (const Vec3& p : target.x) {
    im.front = std::min(im.front, im.direction * p[im.axis]);
    im.rear = std::max(im.rear, im.direction * p[im.axis]);
  }
  return im;
}

}  // namespace mpm
