#pragma once
// Runs a shell command for the CLI tests, capturing its exit status, stdout and stderr; reads
// a result stream's history rows and mpm-post's CSV.
#include <sys/wait.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "mpm/stream/stream.hpp"

namespace mpm::testing {

struct Result {
  int status = -1;
  std::string out, err;
};

inline std::string slurp(const std::filesystem::path& p) {
  std::ifstream f(p, std::ios::binary);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

/// A fresh temporary directory for one test.
inline std::filesystem::path temp_dir(const std::string& name) {
  auto d = std::filesystem::path(MPM_BINARY_DIR) / "tmp" / name;
  std::filesystem::remove_all(d);
  std::filesystem::create_directories(d);
  return d;
}

/// Runs `cmd` with bash (pipefail on), stdout and stderr to files in `dir`.
inline Result run(const std::string& cmd, const std::filesystem::path& dir) {
  const auto out = dir / "stdout.txt", err = dir / "stderr.txt";
  const std::string full =
      "bash -o pipefail -c '" + cmd + "' >" + out.string() + " 2>" + err.string() + " </dev/null";
  const int rc = std::system(full.c_str());
  Result r;
  r.status = WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
  r.out = slurp(out);
  r.err = slurp(err);
  return r;
}

/// The number after "key": in a tool's --json output; NaN when the key is absent.
inline double json_value(const std::string& json, const std::string& key) {
  std::smatch m;
  const std::regex re("\"" + key + "\": ([-0-9.eE+]+)");
  if (!std::regex_search(json, m, re)) return NAN;
  return std::stod(m[1]);
}

/// A CSV as mpm-post writes it: "#" comment lines (the frame's time, the units), a header of
/// column names, rows of numbers. A cell that is not a number reads as NaN.
struct Csv {
  std::vector<std::string> names;
  std::vector<std::vector<double>> rows;
  /// The index of column `name`; -1 when there is none.
  int col(const std::string& name) const {
    for (std::size_t k = 0; k < names.size(); ++k)
      if (names[k] == name) return int(k);
    return -1;
  }
  /// Column `name` of every row (NaN where a row is short of it).
  std::vector<double> column(const std::string& name) const {
    const int k = col(name);
    std::vector<double> v;
    for (const auto& r : rows) v.push_back(k >= 0 && std::size_t(k) < r.size() ? r[k] : NAN);
    return v;
  }
};

/// `text` (mpm-post's stdout) read as a Csv.
inline Csv read_csv(const std::string& text) {
  Csv t;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) {
    if (line.empty() || line[0] == '#') continue;
    std::vector<std::string> cells;
    std::istringstream f(line);
    for (std::string cell; std::getline(f, cell, ',');) cells.push_back(cell);
    if (t.names.empty()) {
      t.names = std::move(cells);
      continue;
    }
    std::vector<double> row;
    for (const auto& c : cells) {
      char* end = nullptr;
      const double x = std::strtod(c.c_str(), &end);
      row.push_back(end != c.c_str() && *end == '\0' ? x : NAN);
    }
    t.rows.push_back(std::move(row));
  }
  return t;
}

/// Appends a HIST record's rows to `all` (its names and units from the first record).
inline void append_history(HistoryBlock& all, HistoryBlock&& b) {
  if (all.names.empty()) all.names = std::move(b.names), all.units = std::move(b.units);
  all.values.insert(all.values.end(), b.values.begin(), b.values.end());
}

/// Every history row of a result stream.
inline HistoryBlock history_of(const std::filesystem::path& result) {
  HistoryBlock all;
  StreamVisitor v;
  v.want_frames = false;
  v.history = [&](HistoryBlock&& b) { append_history(all, std::move(b)); };
  read_stream(result.string(), v);
  return all;
}

inline const std::string prep = MPM_PREP;
inline const std::string runner = MPM_RUN;
inline const std::string post = MPM_POST;

/// `mpm-prep SCENE PREP_ARGS | mpm-run --progress none -o OUT`, run in `dir`.
inline Result prep_and_run(const std::filesystem::path& scene, const std::string& prep_args,
                           const std::filesystem::path& out, const std::filesystem::path& dir) {
  return run(prep + " " + scene.string() + " " + prep_args + " | " + runner +
                 " --progress none -o " + out.string(),
             dir);
}

}  // namespace mpm::testing
