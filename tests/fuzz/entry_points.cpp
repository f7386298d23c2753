// The fuzzers' entry points (entry_points.hpp): bytes in, the tool's error message out.
#include "entry_points.hpp"

#include <fcntl.h>
#include <unistd.h>
#include <zlib.h>

#include <array>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <vector>

#include "mpm/core/error.hpp"
#include "mpm/core/expression.hpp"
#include "mpm/post/commands.hpp"
#include "mpm/prep/mesh_region.hpp"
#include "mpm/run/restart.hpp"
#include "mpm/scene/scene.hpp"
#include "mpm/stream/grid_record.hpp"
#include "mpm/stream/stream.hpp"

namespace mpm::fuzz {
namespace {

namespace fs = std::filesystem;

/// A directory of this process for the files the readers open by name (in memory when
/// /dev/shm exists), removed when the process ends.
const fs::path& scratch() {
  struct Dir {
    fs::path path;
    Dir() {
      const fs::path base =
          fs::is_directory("/dev/shm") ? fs::path("/dev/shm") : fs::temp_directory_path();
      path = base / ("mpm-fuzz-" + std::to_string(::getpid()));
      fs::create_directories(path);
    }
    ~Dir() {
      std::error_code ec;
      fs::remove_all(path, ec);
    }
  };
  static const Dir dir;
  return dir.path;
}

fs::path write_scratch(const std::string& name, const void* data, std::size_t size) {
  const fs::path p = scratch() / name;
  std::ofstream f(p, std::ios::binary | std::ios::trunc);
  f.write(static_cast<const char*>(data), std::streamsize(size));
  return p;
}

/// stdout goes to /dev/null while it lives (mpm-post prints its reports there).
struct QuietStdout {
  int saved = -1;
  QuietStdout() {
    std::fflush(stdout);
    saved = ::dup(1);
    const int null = ::open("/dev/null", O_WRONLY);
    if (null >= 0) {
      ::dup2(null, 1);
      ::close(null);
    }
  }
  ~QuietStdout() {
    std::fflush(stdout);
    if (saved >= 0) {
      ::dup2(saved, 1);
      ::close(saved);
    }
  }
};

/// Every record of a stream decoded as its readers decode it.
void decode_all(const std::string& path) {
  StreamReader r(path);
  std::uint32_t type = 0;
  while (r.next(type)) {
    switch (static_cast<RecordType>(type)) {
      case RecordType::Frame:
      case RecordType::Escape:
      case RecordType::Rebar:
        (void)r.read_frame();
        break;
      case RecordType::Checkpoint:
        (void)r.read_checkpoint();
        break;
      case RecordType::Grid:
        (void)decode_grid(r.read_payload());
        break;
      case RecordType::History:
        (void)StreamReader::decode_history(r.read_payload());
        break;
      case RecordType::End:
        (void)StreamReader::decode_end(r.read_payload());
        break;
      case RecordType::Scene:
      case RecordType::Info:
        (void)StreamReader::decode_text(r.read_payload());
        break;
      default:
        r.skip();
    }
  }
}

/// The stream as mpm-run --restart and mpm-post summary read it.
std::string read_as_tools(const std::string& path) {
  std::string first;
  auto keep = [&](const std::exception& e) {
    if (first.empty()) first = e.what();
  };
  try {
    decode_all(path);
  } catch (const InputError& e) {
    keep(e);
  }
  try {
    const RestartScan scan = scan_for_restart(path);
    check_restartable(path, scan);
    (void)load_checkpoint(path, scan);
  } catch (const InputError& e) {
    keep(e);
  }
  try {
    QuietStdout quiet;
    SummaryArgs args;
    args.input = path;
    args.json = true;
    (void)post_summary(args);
  } catch (const InputError& e) {
    keep(e);
  }
  return first;
}

/// The bytes with every whole record's CRC recomputed; false when nothing changed.
bool correct_crcs(std::vector<unsigned char>& b) {
  bool changed = false;
  std::size_t at = 16;
  while (b.size() - at >= 12 && at < b.size()) {
    std::uint64_t length = 0;
    std::memcpy(&length, b.data() + at + 4, 8);
    if (length > b.size() - at - 12 || b.size() - at - 12 - length < 4) break;
    const std::size_t body = 12 + std::size_t(length);
    const auto crc = std::uint32_t(crc32_z(crc32_z(0, Z_NULL, 0), b.data() + at, body));
    if (std::memcmp(b.data() + at + body, &crc, 4) != 0) {
      std::memcpy(b.data() + at + body, &crc, 4);
      changed = true;
    }
    at += body + 4;
  }
  return changed;
}

}  // namespace

std::string scene(const std::uint8_t* data, std::size_t size) {
  std::string text(reinterpret_cast<const char*>(data), size);
  std::vector<std::string> overrides;
  const std::string marker = "\n%%set\n";
  if (const auto at = text.find(marker); at != std::string::npos) {
    std::size_t from = at + marker.size();
    while (from < text.size()) {
      const std::size_t end = std::min(text.find('\n', from), text.size());
      overrides.push_back(text.substr(from, end - from));
      from = end + 1;
    }
    text.resize(at + 1);
  }
  try {
    (void)parse_scene(text, "fuzz.toml", scratch().string(), overrides);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

std::string mesh(const std::uint8_t* data, std::size_t size) {
  std::string errors;
  for (const char* ext : {".stl", ".obj", ".off"}) {
    Scene s;
    s.source = "fuzz.toml";
    BodySpec body;
    body.name = "part";
    body.shape = ShapeKind::Mesh;
    body.mesh_path = write_scratch(std::string("mesh") + ext, data, size).string();
    body.loc = {"fuzz.toml", 1, "bodies.part"};
    s.bodies.push_back(body);
    try {
      Vec3 lo, hi;
      mesh_body_bounds(body, s, lo, hi);
      const MeshRegion region(body, s);
      region.bounds(lo, hi);
      (void)region.volume();
      (void)region.contains(0.5 * (lo + hi));
      (void)region.classify_box(lo, 0.5 * (lo + hi));
      return "";  // read whole in one of the formats
    } catch (const InputError& e) {
      errors += std::string(errors.empty() ? "" : "\n") + e.what();
    }
  }
  return errors;
}

std::string stream(const std::uint8_t* data, std::size_t size) {
  const fs::path p = write_scratch("stream.mpm", data, size);
  std::string first = read_as_tools(p.string());
  std::vector<unsigned char> fixed(data, data + size);
  if (correct_crcs(fixed)) {
    const fs::path q = write_scratch("stream.mpm", fixed.data(), fixed.size());
    const std::string second = read_as_tools(q.string());
    if (first.empty()) first = second;
  }
  return first;
}

std::string expression(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  const std::vector<std::string>& names = field_variables();
  std::vector<double> values(names.size(), 0.0);
  try {
    const Expression f(text, names, values.data());
    for (double x : {0.0, 1e-3, -2.5, 1e300}) {
      for (std::size_t k = 0; k < values.size(); ++k) values[k] = x * double(k + 1);
      (void)f.eval();
    }
  } catch (const ExpressionError& e) {
    return describe(e, text);
  }
  return "";
}

}  // namespace mpm::fuzz
