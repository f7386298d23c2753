// The columns a rank sends another (ranks.hpp): rows packed column after column, the schema
// of an empty store, and the frames gathered at the root in particle-id order.
#include "mpm/solver/ranks.hpp"

#include <algorithm>
#include <cstring>
#include <numeric>
#include <stdexcept>

namespace mpm {

void pack_rows(const ColumnStore& cols, const std::vector<std::uint32_t>& rows, std::string& out) {
  const std::size_t start = out.size();
  out.resize(start + rows.size() * cols.element_bytes());
  char* o = out.data() + start;
  for (const Column& c : cols.columns()) {
    const std::size_t w = c.info().element_bytes();
    const auto* d = reinterpret_cast<const char*>(c.data());
    for (auto r : rows) std::memcpy(o, d + std::size_t(r) * w, w), o += w;
  }
}

void pack_columns(const ColumnStore& cols, std::string& out) {
  out.reserve(out.size() + cols.bytes());
  for (const Column& c : cols.columns())
    if (c.bytes() > 0) out.append(reinterpret_cast<const char*>(c.data()), c.bytes());
}

void append_rows(ColumnStore& cols, const char* bytes, std::size_t size) {
  if (size == 0) return;
  const std::size_t w = cols.element_bytes();
  if (w == 0 || size % w != 0)
    throw std::runtime_error("ranks: a message of particle rows does not match the columns");
  const std::size_t k = size / w, n0 = cols.size();
  cols.resize(n0 + k);
  const char* in = bytes;
  for (Column& c : cols.columns()) {
    const std::size_t cw = c.info().element_bytes();
    std::memcpy(reinterpret_cast<char*>(c.data()) + n0 * cw, in, k * cw);
    in += k * cw;
  }
}

std::string pack_schema(const ColumnStore& cols) {
  std::string s;
  for (const Column& c : cols.columns()) {
    const ColumnInfo& i = c.info();
    s += i.name + '\n' + std::to_string(int(i.type)) + ' ' + std::to_string(i.components) + '\n' +
         i.unit + '\n';
  }
  return s;
}

void add_schema(ColumnStore& cols, const std::string& schema) {
  Fields f(schema);
  while (!f.done()) {
    ColumnInfo i;
    i.name = f.next();
    const std::string tc = f.next();
    i.type = ScalarType(std::stoi(tc));
    i.components = std::stoi(tc.substr(tc.find(' ') + 1));
    i.unit = f.next();
    cols.add(i);
  }
}

void gather_by_id(const Comm& comm, const ColumnStore& cols, ColumnStore& out) {
  // Each part: its schema's length (8 bytes), the schema, the rows (a rank whose store has no
  // columns yet, such as an empty escape log, sends none).
  const std::string schema = pack_schema(cols);
  const std::uint64_t len = schema.size();
  std::string mine(reinterpret_cast<const char*>(&len), sizeof len);
  mine += schema;
  pack_columns(cols, mine);
  std::vector<std::size_t> at;
  const std::string parts = comm.gather(mine, at);
  std::string().swap(mine);
  out = ColumnStore();
  if (!comm.root()) return;
  for (std::size_t r = 0; r + 1 < at.size(); ++r) {
    std::uint64_t l = 0;
    std::memcpy(&l, parts.data() + at[r], sizeof l);
    if (l == 0) continue;
    if (out.columns().empty()) {
      add_schema(out, parts.substr(at[r] + sizeof l, l));
      out.reserve((parts.size() - at[r]) / std::max<std::size_t>(1, out.element_bytes()));
    }
    append_rows(out, parts.data() + at[r] + sizeof l + l, at[r + 1] - at[r] - sizeof l - l);
  }
  const std::uint32_t* id = out.get<std::uint32_t>(col::id);
  if (!id) return;
  // Ids are unique, and dense unless many particles left: a counting sort when they fit twice
  // the rows, else a comparison sort.
  const std::size_t n = out.size();
  std::uint32_t top = 0;
  for (std::size_t i = 0; i < n; ++i) top = std::max(top, id[i]);
  std::vector<std::uint32_t> order;
  if (n > 0 && std::size_t(top) < 2 * n + 1024) {
    std::vector<std::uint32_t> slot(std::size_t(top) + 1, std::uint32_t(-1));
    for (std::size_t i = 0; i < n; ++i) slot[id[i]] = std::uint32_t(i);
    order.reserve(n);
    for (auto i : slot)
      if (i != std::uint32_t(-1)) order.push_back(i);
  }
  if (order.size() != n) {  // not unique after all: keep every row, by id then rank
    order.resize(n);
    std::iota(order.begin(), order.end(), 0u);
    std::stable_sort(order.begin(), order.end(),
                     [&](std::uint32_t a, std::uint32_t b) { return id[a] < id[b]; });
  }
  out.gather(order);
}

}  // namespace mpm
