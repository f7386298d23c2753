// The GRID record: a graded grid's cells and nodes as stored in streams (docs/format.md).
#include "mpm/stream/grid_record.hpp"

#include <bit>
#include <cstring>

#include "mpm/core/error.hpp"

namespace mpm {

// ------------------------------------------------------------------------------------------
// GRID record payload (docs/format.md):
//   i64 step, f64 time, u16 dim, u16 levels, u32 reserved, u64 nodes, u64 cells, u64 optional,
//   nodes x 3 f64 positions, cells u8 levels, cells x 2^dim u32 corners, cells u32 masks,
//   optional u32 node indices.

namespace {

void put_bytes(std::vector<std::byte>& b, const void* p, std::size_t n) {
  if (n == 0) return;
  const std::size_t at = b.size();
  b.resize(at + n);
  std::memcpy(b.data() + at, p, n);
}
template <class T>
void put(std::vector<std::byte>& b, const T& v) {
  put_bytes(b, &v, sizeof(T));
}
template <class T>
void put_all(std::vector<std::byte>& b, const std::vector<T>& v) {
  put_bytes(b, v.data(), v.size() * sizeof(T));
}

struct Reader {
  const std::vector<std::byte>& b;
  std::size_t at = 0;
  void need(std::size_t n) const {
    if (b.size() - at < n)
      throw StreamError("", "malformed GRID payload: " + std::to_string(b.size()) +
                                " bytes, shorter than its header announces");
  }
  template <class T>
  T get() {
    need(sizeof(T));
    T v;
    std::memcpy(&v, b.data() + at, sizeof(T));
    at += sizeof(T);
    return v;
  }
  template <class T>
  void get_all(std::vector<T>& v, std::size_t n) {
    if (n > (b.size() - at) / sizeof(T)) need(n * sizeof(T));
    v.resize(n);
    if (n == 0) return;  // memcpy from or to null (an empty vector's data) is undefined
    std::memcpy(v.data(), b.data() + at, n * sizeof(T));
    at += n * sizeof(T);
  }
};

}  // namespace

std::vector<std::byte> encode_grid(const GridMesh& g) {
  std::vector<std::byte> b;
  const std::size_t corners = std::size_t(1) << g.dim;
  b.reserve(48 + g.x.size() * 8 + g.cells() * (1 + 4 * corners + 4) + g.optional.size() * 4);
  put(b, std::int64_t(g.step));
  put(b, g.time);
  put(b, std::uint16_t(g.dim));
  put(b, std::uint16_t(g.levels));
  put(b, std::uint32_t(0));
  put(b, std::uint64_t(g.nodes()));
  put(b, std::uint64_t(g.cells()));
  put(b, std::uint64_t(g.optional.size()));
  put_all(b, g.x);
  put_all(b, g.level);
  put_all(b, g.corners);
  put_all(b, g.mask);
  put_all(b, g.optional);
  return b;
}

GridMesh decode_grid(const std::vector<std::byte>& payload) {
  Reader r{payload};
  GridMesh g;
  g.step = r.get<std::int64_t>();
  g.time = r.get<double>();
  g.dim = r.get<std::uint16_t>();
  g.levels = r.get<std::uint16_t>();
  (void)r.get<std::uint32_t>();
  const auto nodes = r.get<std::uint64_t>(), cells = r.get<std::uint64_t>(),
             opt = r.get<std::uint64_t>();
  if (g.dim != 2 && g.dim != 3)
    throw StreamError("", "malformed GRID payload: dimension " + std::to_string(g.dim));
  const std::size_t corners = std::size_t(1) << g.dim;
  const std::size_t need_cells = 1 + 4 * corners + 4;
  if (nodes > payload.size() / 24 || cells > payload.size() / need_cells ||
      opt > payload.size() / 4)
    throw StreamError("", "malformed GRID payload: counts exceed its length");
  r.get_all(g.x, 3 * nodes);
  r.get_all(g.level, cells);
  r.get_all(g.corners, cells * corners);
  r.get_all(g.mask, cells);
  r.get_all(g.optional, opt);
  if (r.at != payload.size())
    throw StreamError("", "malformed GRID payload: " + std::to_string(payload.size() - r.at) +
                              " bytes after its data");
  std::size_t sum = 0;
  for (auto m : g.mask) sum += std::popcount(m);
  if (sum != opt)
    throw StreamError("", "malformed GRID payload: optional nodes do not match the masks");
  for (auto c : g.corners)
    if (c >= nodes) throw StreamError("", "malformed GRID payload: node index out of range");
  for (auto c : g.optional)
    if (c >= nodes) throw StreamError("", "malformed GRID payload: node index out of range");
  return g;
}

}  // namespace mpm
