// Checks of mesh files before CGAL reads them (mesh_file_checks.hpp).
#include "mpm/prep/mesh_file_checks.hpp"

#include <cmath>
#include <fstream>
#include <sstream>
#include <vector>

#include "mpm/core/error.hpp"

namespace mpm {

namespace {

/// The next line holding data, as CGAL's OFF scanner takes it: blank lines and lines starting
/// with '#' skipped, the rest of a line after '#' dropped. False at the end of the file.
bool next_data_line(std::istream& in, std::string& line, int& number) {
  while (std::getline(in, line)) {
    ++number;
    const std::size_t first = line.find_first_not_of(" \t\r\f\v");
    if (first == std::string::npos || line[first] == '#') continue;
    if (const std::size_t hash = line.find('#'); hash != std::string::npos) line.resize(hash);
    return true;
  }
  return false;
}

/// Whether v converts to std::size_t with a defined result (and fits OFF's 32-bit indices).
bool whole_index(double v) {
  return std::isfinite(v) && v >= 0 && v < 4294967296.0;
}

}  // namespace

void check_off_faces(const std::string& path, const std::string& at, const std::string& name) {
  std::ifstream in(path, std::ios::binary);
  std::string line;
  int number = 0;
  if (!next_data_line(in, line, number)) return;
  // The header: [ST][C][N][4][n]OFF [BINARY], then (on its line or the next) the counts.
  std::istringstream head(line);
  std::string keyword;
  head >> keyword;
  if (keyword.size() < 3 || keyword.compare(keyword.size() - 3, 3, "OFF") != 0) return;
  const bool n_dimensional = keyword.find('n') != std::string::npos;
  std::string rest;
  std::getline(head, rest);
  if (rest.find("BINARY") != std::string::npos || n_dimensional) return;
  std::istringstream counts(rest);
  long long vertices = -1, faces = -1;
  if (!(counts >> vertices >> faces)) {
    if (!next_data_line(in, line, number)) return;
    std::istringstream next(line);
    if (!(next >> vertices >> faces)) return;
  }
  if (vertices < 0 || faces < 0) return;  // CGAL refuses the header
  for (long long v = 0; v < vertices; ++v)
    if (!next_data_line(in, line, number)) return;
  for (long long f = 0; f < faces; ++f) {
    if (!next_data_line(in, line, number)) return;
    std::istringstream words(line);
    std::vector<double> entries;
    for (double d; words >> d;) entries.push_back(d);
    if (entries.empty()) return;  // CGAL stops reading here
    const std::string where = "mesh " + name + " line " + std::to_string(number) + ": ";
    if (!whole_index(entries[0]) || entries[0] > double(entries.size() - 1))
      throw InputError(at, where +
                               "a face line must start with its number of vertices and list "
                               "that many vertex indices; found '" +
                               line + "'");
    for (std::size_t k = 1; k <= std::size_t(entries[0]); ++k)
      if (!whole_index(entries[k]))
        throw InputError(at, where + "vertex index " + std::to_string(k) +
                                 " of the face is not a vertex number from 0 "
                                 "to " +
                                 std::to_string(vertices - 1) + "; found '" + line + "'");
  }
}

}  // namespace mpm
