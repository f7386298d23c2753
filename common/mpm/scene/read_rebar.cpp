// The scene parser's [[rebar]] tables: straight bars, square-pattern layers and polyline files
// of truss elements (004, section 2: HFEMP). mpm-prep cuts them into elements.
#include <cmath>
#include <string>
#include <string_view>
#include <vector>

#include "mpm/core/error.hpp"
#include "mpm/scene/read_sections.hpp"

namespace mpm::scene_toml {

namespace {

/// The material of a [[rebar]] entry: a scene material with a density and Young's modulus;
/// its yield stress is the strength's A (none for an elastic material).
int read_rebar_material(Reader& r, const Scene& s) {
  const auto name = r.string("material");
  if (!name) r.missing("material", "the name of a [materials.<name>] table, e.g. \"steel\"");
  const int m = s.material_index(*name);
  if (m < 0) {
    std::vector<std::string_view> known;
    for (const auto& mat : s.materials) known.push_back(mat.name);
    r.fail("material", "unknown material '" + *name + "' (known: " + join(known) + ")");
  }
  return m;
}

/// The body the bars lie in: named, or the first deformable body.
int read_rebar_body(Reader& r, const Scene& s, bool required) {
  const auto name = r.string("body");
  if (!name) {
    if (required) r.missing("body", "the body whose bounding box places the layer, e.g. \"slab\"");
    for (std::size_t b = 0; b < s.bodies.size(); ++b)
      if (!s.bodies[b].rigid) return int(b);
    r.fail_table("rebar needs a deformable body to lie in (its nodes count as that body's)");
  }
  const int b = s.body_index(*name);
  if (b < 0) {
    std::vector<std::string_view> known;
    for (const auto& body : s.bodies) known.push_back(body.name);
    r.fail("body", "unknown body '" + *name + "' (known: " + join(known) + ")");
  }
  if (s.bodies[b].rigid) r.fail("body", "rebar cannot lie in a rigid body");
  return b;
}

void read_layer(Reader& r, RebarSpec& b) {
  b.normal = *r.choice<int>("normal", {{"x", 0}, {"y", 1}, {"z", 2}});
  if (auto off = r.quantity("offset", dim::length)) {
    b.offset_given = true;
    b.offset = *off;
    r.reject({"cover", "face"}, "with offset (the plane's coordinate is given)");
  } else {
    const auto cover = r.quantity("cover", dim::length, Bound::NonNegative);
    if (!cover)
      r.missing("offset", "the plane's coordinate along the normal, e.g. \"25 mm\" (or cover)");
    b.cover = *cover;
    b.cover_from_max = r.choice<bool>("face", {{"min", false}, {"max", true}}).value_or(false);
  }
  b.pitch = r.required("pitch", dim::length, Bound::Positive, "76.2 mm");
  const toml::node* count = r.get("count");
  if (!count) r.missing("count", "the bars of the two families, e.g. [4, 4]");
  const auto* arr = count->as_array();
  if (!arr || arr->size() != 2 || !(*arr)[0].is_integer() || !(*arr)[1].is_integer())
    r.fail("count", "expected two integers (bars parallel to each in-plane axis), " + got(*count));
  for (int k = 0; k < 2; ++k) {
    const long long n = (*arr)[std::size_t(k)].as_integer()->get();
    if (n < 0 || n > 100000)
      r.fail("count", "each count must be in [0, 100000], got " + std::to_string(n));
    b.count[k] = int(n);
  }
  if (b.count[0] + b.count[1] == 0) r.fail("count", "the layer holds no bar");
  if (auto first = r.vector("first", dim::length, 2)) {
    b.first_given = true;
    b.first = {(*first)[0], (*first)[1]};
  }
}

RebarSpec read_rebar(Reader& r, const Scene& s) {
  RebarSpec b;
  b.loc = r.loc();
  const auto shape = r.choice<RebarShape>(
      "shape",
      {{"bar", RebarShape::Bar}, {"layer", RebarShape::Layer}, {"polyline", RebarShape::Polyline}});
  if (!shape) r.missing("shape", "\"bar\", \"layer\" or \"polyline\"");
  b.shape = *shape;
  b.material = read_rebar_material(r, s);
  const MaterialSpec& mat = s.materials[b.material];
  b.body = read_rebar_body(r, s, b.shape == RebarShape::Layer);
  b.diameter = r.required("diameter", dim::length, Bound::Positive, "5.59 mm");
  b.element_length = r.quantity("element_length", dim::length, Bound::Positive).value_or(0.0);
  b.erosion_strain = mat.failure.plastic_strain;
  if (auto e = r.number("erosion_strain", Bound::Positive)) b.erosion_strain = *e;
  switch (b.shape) {
    case RebarShape::Bar: {
      const auto a = r.vector("start", dim::length, 3);
      const auto e = r.vector("end", dim::length, 3);
      if (!a) r.missing("start", "the bar's first end, e.g. \"0 0 25 mm\"");
      if (!e) r.missing("end", "the bar's other end, e.g. \"300 0 25 mm\"");
      r.check("end", (*e - *a).norm() > 0, "must differ from start");
      b.start = *a, b.end = *e;
      r.reject({"normal", "offset", "cover", "face", "pitch", "count", "first", "file"},
               "by a bar (shape = \"bar\": start, end)");
      break;
    }
    case RebarShape::Layer:
      read_layer(r, b);
      r.reject({"start", "end", "file"}, "by a layer (shape = \"layer\")");
      break;
    case RebarShape::Polyline: {
      const auto file = r.string("file");
      if (!file || file->empty())
        r.missing("file", "a text file of x y z points (m), e.g. \"bars.txt\"");
      b.path = *file;
      r.reject({"start", "end", "normal", "offset", "cover", "face", "pitch", "count", "first"},
               "by a polyline (shape = \"polyline\": file)");
      break;
    }
  }
  r.finish();
  return b;
}

}  // namespace

void read_rebars(Reader& top, Scene& s) {
  const toml::node* node = top.get("rebar");
  if (!node) return;
  const auto* arr = node->as_array();
  if (!arr)
    top.fail("rebar",
             "expected an array of tables ([[rebar]], note the double brackets), " + got(*node));
  const Doc& doc = top.doc();
  const Origin array_origin = top.origin_of(*node);
  for (std::size_t i = 0; i < arr->size(); ++i) {
    const toml::node& e = (*arr)[i];
    const std::string path = "rebar." + std::to_string(i);
    const Origin o = doc.origin(e, array_origin);
    const auto* t = e.as_table();
    if (!t) throw InputError(doc.where(o, path), "expected a table ([[rebar]]), " + got(e));
    Reader r(doc, *t, path, o,
             {"shape", "material", "body", "diameter", "element_length", "erosion_strain", "start",
              "end", "normal", "offset", "cover", "face", "pitch", "count", "first", "file"});
    s.rebars.push_back(read_rebar(r, s));
  }
}

}  // namespace mpm::scene_toml
