// Particle columns: the gather that puts particles in cell order keeps every value and never
// grows a column's storage, however many times it runs.
#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <numeric>
#include <random>
#include <vector>

#include "mpm/core/columns.hpp"

namespace mpm {
namespace {

TEST(Columns, GatherPermutesEveryColumnAndKeepsStorageSizes) {
  const std::size_t n = 10000;
  ColumnStore cols;
  cols.add({"sigma", ScalarType::F64, 6, "Pa"});
  cols.add({"x", ScalarType::F64, 3, "m"});
  cols.add({"m", ScalarType::F64, 1, "kg"});
  cols.add({"id", ScalarType::U32, 1, "-"});
  cols.add({"material", ScalarType::U8, 1, "-"});
  cols.resize(n);
  auto fill = [&]() {
    auto* s = cols.get<std::array<double, 6>>("sigma");
    auto* x = cols.get<std::array<double, 3>>("x");
    double* m = cols.get<double>("m");
    auto* id = cols.get<std::uint32_t>("id");
    auto* mat = cols.get<std::uint8_t>("material");
    for (std::size_t i = 0; i < n; ++i) {
      for (int k = 0; k < 6; ++k) s[i][k] = double(i) + 0.1 * k;
      for (int k = 0; k < 3; ++k) x[i][k] = -double(i) - 0.01 * k;
      m[i] = 2.0 * double(i);
      id[i] = std::uint32_t(i);
      mat[i] = std::uint8_t(i % 251);
    }
  };
  fill();
  std::vector<std::size_t> capacity;
  for (const auto& c : cols.columns()) capacity.push_back(c.capacity_bytes());

  std::mt19937 rng(7);
  std::vector<std::uint32_t> perm(n);
  for (int round = 0; round < 12; ++round) {
    // Each element's id says which original element it holds; check every column agrees.
    std::iota(perm.begin(), perm.end(), 0u);
    std::shuffle(perm.begin(), perm.end(), rng);
    cols.gather(perm);
    const auto* s = cols.get<std::array<double, 6>>("sigma");
    const auto* x = cols.get<std::array<double, 3>>("x");
    const double* m = cols.get<double>("m");
    const auto* id = cols.get<std::uint32_t>("id");
    const auto* mat = cols.get<std::uint8_t>("material");
    for (std::size_t i = 0; i < n; ++i) {
      const double o = id[i];
      ASSERT_EQ(s[i][5], o + 0.5);
      ASSERT_EQ(x[i][2], -o - 0.02);
      ASSERT_EQ(m[i], 2.0 * o);
      ASSERT_EQ(mat[i], std::uint8_t(id[i] % 251));
    }
    // Storage per column is what it was: a narrow column never inherits a wide buffer.
    for (std::size_t c = 0; c < cols.columns().size(); ++c)
      ASSERT_EQ(cols.columns()[c].capacity_bytes(), capacity[c]) << cols.columns()[c].info().name;
  }
}

}  // namespace
}  // namespace mpm
