// Checks of mesh files before CGAL reads them (mesh_file_checks.hpp). The OFF check follows
// CGAL 5.5's OFF scanner step by step (File_header_OFF's operator>>, File_scanner_OFF's
// scan_vertex and scan_facet), so that it sees the lines CGAL will see.
#include "mpm/prep/mesh_file_checks.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>
#include <vector>

#include "mpm/core/error.hpp"

namespace mpm {

namespace {

/// CGAL's skip_comment_OFF: skips white space and lines starting with '#'.
void skip_comment(std::istream& in) {
  char c = 0;
  while ((in >> c) && c == '#') in.ignore(std::numeric_limits<std::streamsize>::max(), '\n');
  if (in) in.putback(c);
}

/// The next line as CGAL's scanner reads a vertex or a face: comments skipped, the rest of
/// the line after '#' dropped. False at the end of the file.
bool next_line(std::istream& in, std::string& line) {
  skip_comment(in);
  if (!std::getline(in, line)) return false;
  if (const std::size_t hash = line.find('#'); hash != std::string::npos) line.resize(hash);
  return true;
}

/// Whether v converts to std::size_t with a defined result (and fits OFF's 32-bit indices).
bool whole_index(double v) {
  return std::isfinite(v) && v >= 0 && v < 4294967296.0;
}

}  // namespace

void check_off_faces(const std::string& path, const std::string& at, const std::string& name) {
  std::ifstream file(path, std::ios::binary);
  std::stringstream buffer;
  buffer << file.rdbuf();
  const std::string text = buffer.str();
  std::istringstream in(text);
  auto line_of = [&]() {
    const auto pos = in.tellg() < 0 ? std::streamoff(text.size()) : std::streamoff(in.tellg());
    return 1 + std::count(text.begin(), text.begin() + pos, '\n');
  };
  // The header: comments, then the keyword (letters and digits), then the counts (vertices,
  // faces, edges).
  char c = 0;
  while ((in >> c) && c == '#') in.ignore(std::numeric_limits<std::streamsize>::max(), '\n');
  if (!in) return;
  std::string keyword(1, c);
  while (keyword.size() < 41 && in.get(c) && std::isalnum(static_cast<unsigned char>(c)))
    keyword += c;
  // Only plain OFF: CGAL reads the texture, colour, normal and homogeneous entries of the
  // variants ([ST][C][N][4][n]OFF) without checking that a line holds them (fuzz_mesh: STOFF
  // read past a vertex line's entries), and mpm-prep needs none of them.
  if (keyword != "OFF")
    throw InputError(at, "mesh " + name + " starts with '" + keyword +
                             "', not OFF: only plain OFF files are read (no texture, colour, "
                             "normal or homogeneous variants); save it as plain OFF, STL or OBJ");
  skip_comment(in);
  if (!in.get(c) || !std::isdigit(static_cast<unsigned char>(c))) return;  // BINARY
  in.putback(c);
  long long vertices = 0, faces = 0;
  int n = 0;
  in >> n;
  vertices = n;
  if (!(in >> n)) return;
  faces = n;
  const std::string where = "mesh " + name;
  // Each vertex and face takes a line: a count beyond the file's size would only make CGAL
  // allocate for it (a negative one wraps round to 2^64).
  if (vertices < 0 || faces < 0 || std::size_t(vertices) > text.size() ||
      std::size_t(faces) > text.size())
    throw InputError(at, where + ": its header announces " + std::to_string(vertices) +
                             " vertices and " + std::to_string(faces) + " faces, which its " +
                             std::to_string(text.size()) + " bytes cannot hold");
  if (!(in >> n)) return;  // the edge count; the first vertex is the next line CGAL reads
  std::string line;
  for (long long v = 0; v < vertices; ++v)
    if (!next_line(in, line)) return;
  for (long long f = 0; f < faces; ++f) {
    if (!next_line(in, line)) return;
    std::istringstream words(line);
    std::vector<double> entries;
    for (double d; words >> d;) entries.push_back(d);
    if (entries.empty()) return;                                    // CGAL stops reading here
    const long long number = in.eof() ? line_of() : line_of() - 1;  // the line just read
    const std::string here = where + " line " + std::to_string(number) + ": ";
    if (!whole_index(entries[0]) || entries[0] > double(entries.size() - 1))
      throw InputError(at, here +
                               "a face line must start with its number of vertices and list "
                               "that many vertex indices; found '" +
                               line + "'");
    for (std::size_t k = 1; k <= std::size_t(entries[0]); ++k)
      if (!whole_index(entries[k]))
        throw InputError(at, here + "vertex index " + std::to_string(k) +
                                 " of the face is not a vertex number from 0 to " +
                                 std::to_string(vertices - 1) + "; found '" + line + "'");
  }
}

}  // namespace mpm
