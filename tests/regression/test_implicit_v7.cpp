// The V7 examples (examples/implicit) with the implicit solver through the whole pipeline,
// against analytic values or the explicit solver's (reference values and tolerances, with
// where they come from, in implicit_v7.toml).
#include <gtest/gtest.h>
#include <toml++/toml.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>

#include "cli/run_command.hpp"

namespace mpm {
namespace {

using namespace mpm::testing;
namespace fs = std::filesystem;

/// Rows of mpm-post's CSV, by column name.
std::vector<std::map<std::string, double>> csv(const std::string& text) {
  const Csv t = read_csv(text);
  std::vector<std::map<std::string, double>> rows;
  for (const auto& r : t.rows) {
    std::map<std::string, double> row;
    for (std::size_t k = 0; k < r.size() && k < t.names.size(); ++k) row[t.names[k]] = r[k];
    rows.push_back(row);
  }
  return rows;
}

struct Case {
  toml::table ref;
  fs::path dir, stream;
};

/// Runs the case's scene with its --set overrides; the stream is dir/run.mpm.
Case run_case(const std::string& name) {
  Case c;
  const toml::table all =
      toml::parse_file((fs::path(__FILE__).parent_path() / "implicit_v7.toml").string());
  c.ref = *all[name].as_table();
  c.dir = temp_dir("implicit_v7_" + name);
  c.stream = c.dir / "run.mpm";
  std::string sets, body_sets;  // bodies are mpm-prep's; the rest may go to either
  for (const auto& s : *c.ref["sets"].as_array()) {
    const std::string set = *s.value<std::string>();
    (set.rfind("bodies.", 0) == 0 ? body_sets : sets) += " --set " + set;
  }
  const fs::path scene = fs::path(MPM_EXAMPLES) / c.ref["scene"].value_or(std::string());
  const Result r = run(prep + " " + scene.string() + body_sets + " | " + runner +
                           " --threads 1 --progress none --set output.frames=1" + sets + " -o " +
                           c.stream.string(),
                       c.dir);
  EXPECT_EQ(r.status, 0) << r.err;
  return c;
}

/// The deformable particles of the last frame.
std::vector<std::map<std::string, double>> material(
    const Case& c, const std::string& columns = "x,m,sigma,material") {
  const Result r = run(post + " particles " + c.stream.string() + " --columns " + columns, c.dir);
  EXPECT_EQ(r.status, 0) << r.err;
  auto rows = csv(r.out);
  std::erase_if(rows, [](auto& p) { return p["material"] == 255; });
  return rows;
}

/// sigma_xx on the mesh, as the seed graphs it (001, Fig. 1b): the mass-weighted projection
/// of the particles' stress onto the nodes of the bar's interior rows (y = 0.2 and 0.3, bilinear
/// weights, cells of 0.1), at the nodes x = 0.4 ... 0.7 along the bar.
std::vector<double> nodal_sxx(const std::vector<std::map<std::string, double>>& rows) {
  const double h = 0.1;
  std::map<std::pair<int, int>, std::pair<double, double>> acc;  // (i, j) -> (sum w s, sum w)
  for (const auto& p : rows) {
    const double x = p.at("x_0") / h, y = p.at("x_1") / h;
    const int i = int(x), j = int(y);
    const double fx = x - i, fy = y - j;
    for (int di = 0; di < 2; ++di)
      for (int dj = 0; dj < 2; ++dj) {
        const double w = p.at("m") * (di ? fx : 1 - fx) * (dj ? fy : 1 - fy);
        auto& a = acc[{i + di, j + dj}];
        a.first += w * p.at("sigma_0");
        a.second += w;
      }
  }
  std::vector<double> out;
  for (int j : {2, 3})
    for (int i = 4; i <= 7; ++i) {
      const auto& a = acc[{i, j}];
      EXPECT_GT(a.second, 0) << "node " << i << ", " << j;
      out.push_back(a.first / a.second);
    }
  return out;
}

void bar(const std::string& name) {
  const Case c = run_case(name);
  const auto rows = material(c);
  if (c.ref["nodal_sigma_xx"]) {
    const double expect = c.ref["nodal_sigma_xx"].value_or(0.0);
    const auto nodal = nodal_sxx(rows);
    const auto [lo, hi] = std::minmax_element(nodal.begin(), nodal.end());
    for (double s : nodal) EXPECT_NEAR(s, expect, c.ref["nodal_tolerance"].value_or(0.0) * expect);
    EXPECT_LT((*hi - *lo) / expect, c.ref["nodal_spread"].value_or(0.0)) << "uniform along the bar";
    // mpm-post profile --grid gives the same nodal values (the row y = 0.2, x = 0.4 ... 0.7).
    const Result r = run(post + " profile " + c.stream.string() +
                             " --grid --body bar --field sigma --component xx --from \"0.4 0.2\" "
                             "--to \"0.7 0.2\" --radius 1e-6",
                         c.dir);
    ASSERT_EQ(r.status, 0) << r.err;
    const auto prof = csv(r.out);
    ASSERT_EQ(prof.size(), 4u);
    for (std::size_t k = 0; k < 4; ++k) {
      EXPECT_NEAR(prof[k].at("s"), 0.1 * double(k), 1e-9);
      EXPECT_NEAR(prof[k].at("value"), nodal[k], 1e-9 * std::abs(nodal[k]));
    }
  }
  if (c.ref["thickness_tolerance"]) {  // plane stress: ln(h / h0) = eps_zz = -nu / E (s_xx + s_yy)
    const double E = c.ref["youngs_modulus"].value_or(0.0),
                 nu = c.ref["poisson_ratio"].value_or(0.0);
    for (auto& p : material(c, "x,sigma,thickness,material")) {
      const double ezz = -nu / E * (p.at("sigma_0") + p.at("sigma_1"));
      EXPECT_NEAR(std::log(p.at("thickness")), ezz,
                  c.ref["thickness_tolerance"].value_or(0.0) * std::abs(ezz));
    }
  }
  ASSERT_EQ(rows.size(), 36u);
  double sum = 0, lo = 1e300, hi = -1e300;
  for (auto& p : rows) {
    sum += p.at("sigma_0");
    lo = std::min(lo, p.at("sigma_0"));
    hi = std::max(hi, p.at("sigma_0"));
  }
  const double mean = sum / rows.size(), expect = c.ref["sigma_xx"].value_or(0.0);
  EXPECT_NEAR(mean, expect, c.ref["tolerance"].value_or(0.0) * expect);
  EXPECT_LT((hi - lo) / mean, c.ref["spread"].value_or(0.0)) << "uniform along the bar";
}

TEST(RegressionImplicit, ElasticBarV7) {
  bar("elastic_bar");
}
TEST(RegressionImplicit, PlasticBarV7) {
  bar("plastic_bar");
}
TEST(RegressionImplicit, ElasticBarExplicitSolverV7) {
  bar("elastic_bar_explicit");
}
TEST(RegressionImplicit, PlasticBarExplicitSolverV7) {
  bar("plastic_bar_explicit");
}
TEST(RegressionImplicit, ElasticBarStickingEndsV7) {
  bar("elastic_bar_sticking");
}
TEST(RegressionImplicit, PlasticBarStickingEndsV7) {
  bar("plastic_bar_sticking");
}

// Newton's initial guess: the last step's converged grid velocities (initial_guess =
// "previous", the velocity formulation's default) against the seed's v^k from the particles,
// on the plastic bar with Newton-CG at 10x (the seed's Table 3 case whose cost ratio v^k left
// above the seed's: one Newton iteration every step). The same bar within the Newton
// tolerance (stress agreement 1e-5 relative asserted; measured 6e-8) for fewer residual
// evaluations (measured 2597 -> 1220: at least 30% fewer asserted; deterministic counts).
TEST(RegressionImplicit, PreviousStepGuessSavesNewtonWork) {
  std::map<std::string, std::pair<double, double>> got;  // guess -> (evaluations, sigma_xx)
  for (const std::string guess : {"particles", "previous"}) {
    const Case c = run_case("guess_" + guess);
    const Result h =
        run(post + " history " + c.stream.string() + " --columns residual_evals_total", c.dir);
    ASSERT_EQ(h.status, 0) << h.err;
    double sum = 0;
    const auto rows = material(c, "sigma,material");
    for (const auto& p : rows) sum += p.at("sigma_0");
    got[guess] = {csv(h.out).back().at("residual_evals_total"), sum / rows.size()};
  }
  const auto& [e_part, s_part] = got["particles"];
  const auto& [e_prev, s_prev] = got["previous"];
  EXPECT_NEAR(s_prev, s_part, 1e-5 * std::abs(s_part));
  EXPECT_LT(e_prev, 0.7 * e_part) << "particles: " << e_part << ", previous: " << e_prev;
}

TEST(RegressionImplicit, CollidingDisksV7) {
  const Case c = run_case("disks");
  const Result r = run(post + " history " + c.stream.string() + " --columns time,total", c.dir);
  ASSERT_EQ(r.status, 0) << r.err;
  const auto rows = csv(r.out);
  ASSERT_GT(rows.size(), 100u);
  const double lost = 1 - rows.back().at("total") / rows.front().at("total");
  EXPECT_NEAR(lost, c.ref["energy_lost"].value_or(0.0), c.ref["tolerance"].value_or(0.0));
  for (auto& row : rows) EXPECT_LE(row.at("total"), rows.front().at("total") * (1 + 1e-9));
}

/// The platen load averaged over the run's last 0.5 ms (1 m/s: the last 0.5 mm of travel).
double final_load(const Case& c) {
  const Result r =
      run(post + " history " + c.stream.string() + " --columns time,dt,force_platen_y", c.dir);
  EXPECT_EQ(r.status, 0) << r.err;
  const auto rows = csv(r.out);
  if (rows.empty()) return 0;
  const double t_end = rows.back().at("time");
  double impulse = 0, span = 0;
  for (auto& row : rows)
    if (row.at("time") > t_end - 0.5e-3 && row.at("dt") > 0) {
      impulse += row.at("force_platen_y") * row.at("dt");
      span += row.at("dt");
    }
  EXPECT_GT(span, 0);
  return span > 0 ? impulse / span : 0;
}

TEST(RegressionImplicit, UpsettingV7) {
  const Case c = run_case("upsetting");
  double r_max = 0;
  for (auto& p : material(c)) r_max = std::max(r_max, p.at("x_0"));
  const double r_ref = c.ref["r_max"].value_or(0.0);
  EXPECT_NEAR(r_max, r_ref, c.ref["r_tolerance"].value_or(0.0) * r_ref);
  // Load: time-weighted mean over the last 0.5 mm of platen travel (1 m/s: the last 0.5 ms).
  const double load = final_load(c), load_ref = c.ref["load"].value_or(0.0);
  EXPECT_NEAR(load, load_ref, c.ref["load_tolerance"].value_or(0.0) * load_ref);
}

// One particle per cell: a converged step may not carry a ring across the axis (r < 0); the
// step is cut instead, and the run reaches its end with the explicit solver's load.
TEST(RegressionImplicit, UpsettingOneParticlePerCellKeepsRingsOffTheAxis) {
  const Case c = run_case("upsetting_one_per_cell");
  const Case e = run_case("upsetting_one_per_cell_explicit");
  const auto rows = material(c);
  ASSERT_EQ(rows.size(), 150u);  // 10 x 15 rings, none lost
  for (auto& p : rows) EXPECT_GE(p.at("x_0"), 0.0);
  const double load = final_load(c), explicit_load = final_load(e);
  EXPECT_GT(explicit_load, 1e5);  // the platen is pressing (243 kN)
  EXPECT_NEAR(load, explicit_load, c.ref["load_tolerance"].value_or(0.0) * explicit_load);
}

}  // namespace
}  // namespace mpm
