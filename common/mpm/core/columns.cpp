#include "mpm/core/columns.hpp"

#include <omp.h>

#include <algorithm>
#include <stdexcept>

namespace mpm {

std::size_t scalar_size(ScalarType t) {
  switch (t) {
    case ScalarType::F64:
      return 8;
    case ScalarType::F32:
      return 4;
    case ScalarType::U8:
      return 1;
    case ScalarType::U32:
      return 4;
    case ScalarType::I32:
      return 4;
    case ScalarType::U64:
      return 8;
  }
  throw std::invalid_argument("unknown scalar type code " + std::to_string(int(t)));
}

const char* scalar_name(ScalarType t) {
  switch (t) {
    case ScalarType::F64:
      return "f64";
    case ScalarType::F32:
      return "f32";
    case ScalarType::U8:
      return "u8";
    case ScalarType::U32:
      return "u32";
    case ScalarType::I32:
      return "i32";
    case ScalarType::U64:
      return "u64";
  }
  return "?";
}

void Column::check_view(std::size_t bytes) const {
  if (bytes != info_.element_bytes())
    throw std::logic_error("column '" + info_.name + "' viewed with an element of " +
                           std::to_string(bytes) + " bytes, holds " +
                           std::to_string(info_.element_bytes()));
}

void Column::swap_storage(Buffer& buffer, std::size_t& buffer_bytes) {
  const std::size_t eb = info_.element_bytes();
  if (buffer_bytes < n_ * eb) throw std::logic_error("column buffer swap: buffer too small");
  const std::size_t mine = capacity_ * eb;
  data_.swap(buffer);
  capacity_ = buffer_bytes / eb;
  buffer_bytes = mine;
}

void Column::reserve(std::size_t n) {
  if (n <= capacity_) return;
  const std::size_t eb = info_.element_bytes();
  Buffer fresh(static_cast<std::byte*>(
      ::operator new[](std::max<std::size_t>(n * eb, 64), std::align_val_t(64))));
  if (n_ > 0) std::memcpy(fresh.get(), data_.get(), n_ * eb);
  data_ = std::move(fresh);
  capacity_ = n;
}

void Column::resize(std::size_t n) {
  if (n > capacity_) reserve(std::max(n, capacity_ + capacity_ / 4));
  if (n > n_)
    std::memset(data_.get() + n_ * info_.element_bytes(), 0, (n - n_) * info_.element_bytes());
  n_ = n;
}

Column& ColumnStore::add(const ColumnInfo& info) {
  if (find(info.name)) throw std::logic_error("column '" + info.name + "' exists already");
  if (info.components < 1) throw std::logic_error("column '" + info.name + "' has no components");
  cols_.emplace_back(info);
  cols_.back().resize(n_);
  return cols_.back();
}

Column* ColumnStore::find(const std::string& name) {
  for (auto& c : cols_)
    if (c.info().name == name) return &c;
  return nullptr;
}
const Column* ColumnStore::find(const std::string& name) const {
  for (auto& c : cols_)
    if (c.info().name == name) return &c;
  return nullptr;
}
Column& ColumnStore::at(const std::string& name) {
  if (Column* c = find(name)) return *c;
  throw std::out_of_range("no column '" + name + "'");
}
const Column& ColumnStore::at(const std::string& name) const {
  if (const Column* c = find(name)) return *c;
  throw std::out_of_range("no column '" + name + "'");
}

void ColumnStore::resize(std::size_t n) {
  for (auto& c : cols_) c.resize(n);
  n_ = n;
}
void ColumnStore::reserve(std::size_t n) {
  for (auto& c : cols_) c.reserve(n);
}

void ColumnStore::gather(const std::vector<std::uint32_t>& perm) {
  const std::size_t m = perm.size();
  std::vector<Column*> order;
  for (auto& c : cols_) order.push_back(&c);
  std::stable_sort(order.begin(), order.end(), [](const Column* a, const Column* b) {
    return a->info().element_bytes() > b->info().element_bytes();
  });
  if (order.empty()) {
    n_ = m;
    return;
  }
  const std::size_t widest = order.front()->info().element_bytes() * std::max<std::size_t>(m, 1);
  if (spare_bytes_ < widest) {
    spare_.reset(static_cast<std::byte*>(::operator new[](widest, std::align_val_t(64))));
    spare_bytes_ = widest;
  }
  for (Column* c : order) {
    const std::size_t eb = c->info().element_bytes();
    const std::byte* src = c->data();
    std::byte* dst = spare_.get();
    // Element sizes are small multiples of 1..48 bytes; memcpy of a constant size inlines.
    auto run = [&](auto width) {
      constexpr std::size_t w = decltype(width)::value;
#pragma omp parallel for schedule(static)
      for (std::size_t i = 0; i < m; ++i)
        std::memcpy(dst + i * w, src + std::size_t(perm[i]) * w, w);
    };
    switch (eb) {
      case 1:
        run(std::integral_constant<std::size_t, 1>{});
        break;
      case 4:
        run(std::integral_constant<std::size_t, 4>{});
        break;
      case 8:
        run(std::integral_constant<std::size_t, 8>{});
        break;
      case 16:
        run(std::integral_constant<std::size_t, 16>{});
        break;
      case 24:
        run(std::integral_constant<std::size_t, 24>{});
        break;
      case 48:
        run(std::integral_constant<std::size_t, 48>{});
        break;
      default:
#pragma omp parallel for schedule(static)
        for (std::size_t i = 0; i < m; ++i)
          std::memcpy(dst + i * eb, src + std::size_t(perm[i]) * eb, eb);
    }
    if (m > c->size()) throw std::logic_error("gather: permutation longer than the columns");
    c->resize(m);  // shrinking keeps the storage
    // Swap only buffers of the same size: a narrower column that took the wide spare would
    // keep it, and after a few sorts every column would hold the widest column's bytes (seen
    // as 580 instead of 190 bytes a particle). Otherwise copy back, sequentially.
    if (c->capacity_bytes() == spare_bytes_)
      c->swap_storage(spare_, spare_bytes_);
    else if (m > 0)
      std::memcpy(c->data(), dst, m * eb);
  }
  n_ = m;
}

std::size_t ColumnStore::bytes() const {
  std::size_t b = 0;
  for (auto& c : cols_) b += c.bytes();
  return b;
}
std::size_t ColumnStore::element_bytes() const {
  std::size_t b = 0;
  for (auto& c : cols_) b += c.info().element_bytes();
  return b;
}

}  // namespace mpm
