// Tests of the stream format (common/mpm/stream/stream.hpp, docs/format.md): round trips through
// files, FIFOs and stdin/stdout, f32 precision, field selection, and damage: truncation at
// every byte, a flipped byte anywhere, bad headers, unknown record types, write failures.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zlib.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <mutex>
#include <set>
#include <thread>

#include "mpm/core/error.hpp"
#include "mpm/stream/stream.hpp"

namespace mpm {
namespace {

namespace fs = std::filesystem;
using Bytes = std::string;

/// A temporary directory removed at the end of the test.
struct TempDir {
  fs::path path;
  TempDir() {
    std::string t = (fs::temp_directory_path() / "mpm-stream-XXXXXX").string();
    if (!mkdtemp(t.data())) throw std::runtime_error("mkdtemp failed");
    path = t;
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path, ec);
  }
  std::string file(const std::string& name) const { return (path / name).string(); }
};

Bytes slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return Bytes(std::istreambuf_iterator<char>(in), {});
}
/// Writes a file anew. Removing it first avoids ext4's flush on truncation (auto_da_alloc),
/// which makes thousands of rewrites slow.
void spit(const std::string& path, const Bytes& data) {
  std::remove(path.c_str());
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(data.data(), std::streamsize(data.size()));
}

template <class T>
void set(Column& c, std::size_t i, int k, T v) {
  ASSERT_EQ(sizeof(T), scalar_size(c.info().type));
  std::memcpy(c.data() + (i * c.info().components + k) * sizeof(T), &v, sizeof v);
}
template <class T>
T get(const Column& c, std::size_t i, int k) {
  T v;
  std::memcpy(&v, c.data() + (i * c.info().components + k) * sizeof(T), sizeof v);
  return v;
}

/// A frame with every scalar type and component counts 1, 2, 3 and 6; values that f32 cannot
/// hold exactly, negative integers and u64 beyond 2^53.
Frame make_frame(std::int64_t step, std::size_t n, std::uint32_t flags = 0) {
  Frame f;
  f.step = step;
  f.time = 1e-6 * double(step) / 3.0;
  f.flags = flags;
  ColumnStore& s = f.columns;
  s.add({"x", ScalarType::F64, 3, "m"});
  s.add({"v", ScalarType::F64, 3, "m/s"});
  s.add({"sigma", ScalarType::F64, 6, "Pa"});
  s.add({"mass", ScalarType::F64, 1, "kg"});
  s.add({"normal", ScalarType::F32, 2, "-"});
  s.add({"material", ScalarType::U8, 1, "-"});
  s.add({"id", ScalarType::U32, 1, "-"});
  s.add({"cell", ScalarType::I32, 6, "-"});
  s.add({"key", ScalarType::U64, 2, "-"});
  s.resize(n);
  const double b = 0.1 + double(step);
  for (std::size_t i = 0; i < n; ++i) {
    for (int k = 0; k < 3; ++k) set(s.at("x"), i, k, b + 1.0 / 3.0 * double(i * 3 + k) + 1e-12);
    for (int k = 0; k < 3; ++k) set(s.at("v"), i, k, -b * 7.1 + std::sqrt(2.0) * double(i + k));
    for (int k = 0; k < 6; ++k)
      set(s.at("sigma"), i, k, 1.234567891234e8 * (double(k) - 2.5) + double(i) / 7);
    set(s.at("mass"), i, 0, 1e-9 * (1.0 + double(i) / 11));
    for (int k = 0; k < 2; ++k) set(s.at("normal"), i, k, float(0.3 * double(k + i) - b));
    set(s.at("material"), i, 0, std::uint8_t(200 + i));
    set(s.at("id"), i, 0, std::uint32_t(4000000000u + i));
    for (int k = 0; k < 6; ++k) set(s.at("cell"), i, k, std::int32_t(-1000000 * k + int(i) - 3));
    for (int k = 0; k < 2; ++k)
      set(s.at("key"), i, k, (std::uint64_t(1) << 60) + 12345 * i + k + step);
  }
  return f;
}

/// Checks that `got` is `want` after writing with `fields` and `precision`, and reading
/// (f32 widened, f64 other than "x" rounded to f32 under Float32).
void expect_frame(const Frame& want, const Frame& got, Precision precision = Precision::Float64,
                  std::vector<std::string> fields = {}) {
  EXPECT_EQ(got.step, want.step);
  EXPECT_EQ(got.time, want.time);
  EXPECT_EQ(got.flags, want.flags);
  ASSERT_EQ(got.columns.size(), want.columns.size());
  if (fields.empty())
    for (const Column& c : want.columns.columns()) fields.push_back(c.info().name);
  ASSERT_EQ(got.columns.columns().size(), fields.size());
  const std::size_t n = want.columns.size();
  for (std::size_t j = 0; j < fields.size(); ++j) {
    const Column& w = want.columns.at(fields[j]);
    const Column& g = got.columns.columns()[j];
    const ColumnInfo& wi = w.info();
    SCOPED_TRACE("column " + wi.name);
    EXPECT_EQ(g.info().name, wi.name);
    EXPECT_EQ(g.info().unit, wi.unit);
    EXPECT_EQ(g.info().components, wi.components);
    ASSERT_EQ(g.size(), n);
    if (wi.type == ScalarType::F64 || wi.type == ScalarType::F32) {
      ASSERT_EQ(g.info().type, ScalarType::F64) << "consumers see f64 only";
      const bool narrowed = precision == Precision::Float32 && wi.name != "x";
      for (std::size_t i = 0; i < n; ++i)
        for (int k = 0; k < wi.components; ++k) {
          double e =
              wi.type == ScalarType::F32 ? double(get<float>(w, i, k)) : get<double>(w, i, k);
          if (narrowed) e = double(float(e));
          ASSERT_EQ(get<double>(g, i, k), e) << "element " << i << " component " << k;
        }
    } else {
      ASSERT_EQ(g.info().type, wi.type);
      if (n > 0) {
        ASSERT_EQ(0, std::memcmp(g.data(), w.data(), w.bytes()));
      }
    }
  }
}

HistoryBlock make_history(int rows) {
  HistoryBlock h;
  h.names = {"time", "dt", "kinetic"};
  h.units = {"s", "s", "J"};
  for (int r = 0; r < rows; ++r)
    h.values.insert(h.values.end(), {r * 1e-7, 1e-7 / 3, 0.5 * r * r + 1.0 / 7});
  return h;
}

const std::string kScene = "[scene]\nname = \"taylor\" # Ø 10 mm\n";
const std::string kInfo = "tool = \"mpm-run\"\nversion = \"0.1.0\"\n";

/// The sample stream: SCEN, INFO, 3 frames (the middle one empty), HIST, ENDS.
std::vector<Frame> write_sample(StreamWriter& w, std::size_t n = 3) {
  std::vector<Frame> frames;  // Frame is move-only
  frames.push_back(make_frame(0, n, kFrameModel));
  frames.push_back(make_frame(10, 0));
  frames.push_back(make_frame(20, n + 1, kFrameFinal));
  w.write_text(RecordType::Scene, kScene);
  w.write_text(RecordType::Info, kInfo);
  w.write_frame(frames[0]);
  w.write_frame(frames[1]);
  w.write_history(make_history(4));
  w.write_frame(frames[2]);
  w.write_end(0, "completed");
  return frames;
}

/// Everything a visitor received.
struct Collected {
  std::vector<std::string> scenes, infos;
  std::vector<Frame> frames;
  std::vector<HistoryBlock> histories;
  std::vector<std::pair<int, std::string>> ends;
  StreamVisitor visitor() {
    StreamVisitor v;
    v.scene = [this](const std::string& s) { scenes.push_back(s); };
    v.info = [this](const std::string& s) { infos.push_back(s); };
    v.frame = [this](Frame&& f) { frames.push_back(std::move(f)); };
    v.history = [this](HistoryBlock&& h) { histories.push_back(std::move(h)); };
    v.end = [this](int s, const std::string& m) { ends.emplace_back(s, m); };
    return v;
  }
};

void expect_sample(const Collected& c, const StreamSummary& s, const std::vector<Frame>& frames) {
  EXPECT_EQ(s.damage, "");
  EXPECT_TRUE(s.ended);
  EXPECT_EQ(s.end_status, 0);
  EXPECT_EQ(s.end_message, "completed");
  EXPECT_EQ(s.frames, frames.size());
  ASSERT_EQ(c.scenes, std::vector<std::string>{kScene});
  ASSERT_EQ(c.infos, std::vector<std::string>{kInfo});
  ASSERT_EQ(c.frames.size(), frames.size());
  for (std::size_t i = 0; i < frames.size(); ++i) expect_frame(frames[i], c.frames[i]);
  ASSERT_EQ(c.histories.size(), 1u);
  const HistoryBlock h = make_history(4);
  EXPECT_EQ(c.histories[0].names, h.names);
  EXPECT_EQ(c.histories[0].units, h.units);
  EXPECT_EQ(c.histories[0].values, h.values);
  EXPECT_EQ(c.histories[0].rows(), 4u);
  ASSERT_EQ(c.ends.size(), 1u);
  EXPECT_EQ(c.ends[0], std::make_pair(0, std::string("completed")));
}

/// Record boundaries of a well-formed stream, parsed independently of the reader.
struct Layout {
  struct Rec {
    std::uint32_t type;
    std::size_t begin, end;  ///< [begin, end) including the 12-byte header and the CRC
  };
  std::vector<Rec> records;
  explicit Layout(const Bytes& b) {
    std::size_t at = 16;
    while (at < b.size()) {
      std::uint32_t type;
      std::uint64_t len;
      std::memcpy(&type, b.data() + at, 4);
      std::memcpy(&len, b.data() + at + 4, 8);
      records.push_back({type, at, at + 12 + std::size_t(len) + 4});
      at = records.back().end;
    }
    if (at != b.size()) throw std::runtime_error("layout does not end at the end of the stream");
  }
  /// Frames in records that end at or before `cut`.
  std::size_t frames_before(std::size_t cut) const {
    std::size_t n = 0;
    for (auto& r : records)
      if (r.end <= cut && r.type == std::uint32_t(RecordType::Frame)) ++n;
    return n;
  }
  const Rec& record_at(std::size_t byte) const {
    for (auto& r : records)
      if (byte >= r.begin && byte < r.end) return r;
    throw std::out_of_range("byte outside records");
  }
};

Bytes make_record(const char fourcc[4], const Bytes& payload, bool good_crc = true) {
  Bytes r(fourcc, 4);
  const std::uint64_t len = payload.size();
  r.append(reinterpret_cast<const char*>(&len), 8);
  r += payload;
  std::uint32_t crc =
      std::uint32_t(crc32(0, reinterpret_cast<const Bytef*>(r.data()), uInt(r.size())));
  if (!good_crc) crc ^= 1;
  r.append(reinterpret_cast<const char*>(&crc), 4);
  return r;
}

bool contains(const std::string& s, const std::string& part) {
  return s.find(part) != std::string::npos;
}

// ---------------------------------------------------------------------------------------------

TEST(Stream, RecordNames) {
  EXPECT_EQ(record_name(std::uint32_t(RecordType::Scene)), "SCEN");
  EXPECT_EQ(record_name(std::uint32_t(RecordType::Info)), "INFO");
  EXPECT_EQ(record_name(std::uint32_t(RecordType::Frame)), "FRAM");
  EXPECT_EQ(record_name(std::uint32_t(RecordType::History)), "HIST");
  EXPECT_EQ(record_name(std::uint32_t(RecordType::End)), "ENDS");
  EXPECT_EQ(record_name(0x41525458), "?XTRA");
  EXPECT_EQ(record_name(0x01020304), "?0x01020304");
}

TEST(Stream, HeaderBytes) {
  TempDir d;
  const std::string p = d.file("h.mpm");
  {
    StreamWriter w(p);
    EXPECT_EQ(w.bytes_written(), 16u);
  }
  const Bytes b = slurp(p);
  EXPECT_EQ(b, Bytes("\x89MPM\r\n\x1a\n\x01\x00\x04\x00\x00\x00\x00\x00", 16));  // 1.4
  // A stream with no records reads cleanly, but has not ended.
  Collected c;
  const StreamSummary s = read_stream(p, c.visitor());
  EXPECT_EQ(s.damage, "");
  EXPECT_FALSE(s.ended);
  EXPECT_EQ(s.frames, 0u);
}

TEST(Stream, RecordLayoutAndCrc) {
  TempDir d;
  const std::string p = d.file("r.mpm");
  {
    StreamWriter w(p);
    w.write_end(3, "unstable at step 7");
    EXPECT_EQ(w.bytes_written(), 16u + 12 + 4 + 18 + 4);
  }
  const Bytes b = slurp(p);
  Bytes payload("\x03\x00\x00\x00", 4);
  payload += "unstable at step 7";
  EXPECT_EQ(b.substr(16), make_record("ENDS", payload));
}

TEST(Stream, RoundTripFile) {
  TempDir d;
  const std::string p = d.file("run.mpm");
  std::vector<Frame> frames;
  std::uint64_t written = 0;
  {
    StreamWriter w(p);
    frames = write_sample(w);
    written = w.bytes_written();
    w.close();
  }
  EXPECT_EQ(fs::file_size(p), written);
  Collected c;
  const StreamSummary s = read_stream(p, c.visitor());
  expect_sample(c, s, frames);

  // The same through the record-level API.
  StreamReader r(p);
  std::uint32_t type = 0;
  ASSERT_TRUE(r.next(type));
  EXPECT_EQ(type, std::uint32_t(RecordType::Scene));
  EXPECT_EQ(r.record_offset(), 16u);
  EXPECT_EQ(StreamReader::decode_text(r.read_payload()), kScene);
  ASSERT_TRUE(r.next(type));
  r.skip();  // INFO
  ASSERT_TRUE(r.next(type));
  ASSERT_EQ(type, std::uint32_t(RecordType::Frame));
  expect_frame(frames[0], r.read_frame());
  ASSERT_TRUE(r.next(type));
  r.skip();  // the empty frame, CRC-checked
  EXPECT_EQ(r.frames_read(), 2u);
  ASSERT_TRUE(r.next(type));
  ASSERT_EQ(type, std::uint32_t(RecordType::History));
  EXPECT_EQ(StreamReader::decode_history(r.read_payload()).values, make_history(4).values);
  ASSERT_TRUE(r.next(type));
  // Not reading the frame: next() skips it.
  ASSERT_TRUE(r.next(type));
  ASSERT_EQ(type, std::uint32_t(RecordType::End));
  EXPECT_EQ(StreamReader::decode_end(r.read_payload()),
            std::make_pair(0, std::string("completed")));
  EXPECT_FALSE(r.next(type));
  EXPECT_FALSE(r.next(type));
  EXPECT_EQ(r.records_read(), 7u);
  EXPECT_EQ(r.frames_read(), 3u);
  EXPECT_EQ(r.offset(), written);
}

// A checkpoint (CHKP) keeps its state values and every column exactly, f64 as f64; frame
// readers skip it and do not count it as a frame; a cut anywhere in it is truncation.
TEST(Stream, CheckpointRoundTrip) {
  TempDir d;
  const std::string p = d.file("chkp.mpm");
  StateValues state;
  state.set("time", 1.2345678901234567e-5);
  state.set("step", 9007199254740991.0);  // 2^53 - 1: counts stay exact
  state.set("tiny", std::nextafter(0.0, 1.0));
  const Frame f = make_frame(7, 5);
  {
    StreamWriter w(p);
    w.write_frame(f, {}, Precision::Float32);
    w.write_checkpoint(state, f);
    w.write_end(0, "completed");
  }
  StreamReader r(p);
  std::uint32_t type = 0;
  ASSERT_TRUE(r.next(type));
  r.skip();
  ASSERT_TRUE(r.next(type));
  ASSERT_EQ(type, std::uint32_t(RecordType::Checkpoint));
  EXPECT_EQ(record_name(type), "CHKP");
  const Checkpoint c = r.read_checkpoint();
  ASSERT_EQ(c.state.items().size(), 3u);
  for (const auto& [name, value] : state.items()) EXPECT_EQ(c.state.get(name), value) << name;
  expect_frame(f, c.frame);  // every column, bitwise (Float64)
  EXPECT_EQ(r.frames_read(), 1u);
  EXPECT_THROW(c.state.get("absent"), InputError);
  Collected col;
  const StreamSummary s = read_stream(p, col.visitor());
  EXPECT_EQ(s.damage, "");
  EXPECT_EQ(s.frames, 1u);
  EXPECT_TRUE(s.ended);
  // Cut inside the checkpoint: truncation at that record, the frame before it intact.
  const Bytes b = slurp(p);
  const std::size_t chkp_at = b.find("CHKP");
  ASSERT_NE(chkp_at, Bytes::npos);
  spit(p, b.substr(0, chkp_at + 40));
  const StreamSummary cut = read_stream(p, col.visitor());
  EXPECT_NE(cut.damage.find("truncated in record 2 (CHKP"), std::string::npos) << cut.damage;
  EXPECT_EQ(cut.frames, 1u);
}

TEST(Stream, VisitorWithoutFrames) {
  TempDir d;
  const std::string p = d.file("run.mpm");
  {
    StreamWriter w(p);
    write_sample(w);
  }
  Collected c;
  StreamVisitor v = c.visitor();
  v.want_frames = false;
  const StreamSummary s = read_stream(p, v);
  EXPECT_TRUE(c.frames.empty());
  EXPECT_EQ(s.frames, 3u);  // skipped, but counted and CRC-checked
  EXPECT_TRUE(s.ended);
  EXPECT_EQ(c.histories.size(), 1u);
  // An empty visitor still reads the ENDS status.
  const StreamSummary e = read_stream(p, StreamVisitor{});
  EXPECT_TRUE(e.ended);
  EXPECT_EQ(e.end_message, "completed");
}

TEST(Stream, EndStatusOfAnUnstableRun) {
  TempDir d;
  const std::string p = d.file("run.mpm");
  {
    StreamWriter w(p);
    w.write_frame(make_frame(0, 2));
    w.write_end(kExitUnstable, "unstable at step 12: J < 0 at particle 3");
  }
  const StreamSummary s = read_stream(p, {});
  EXPECT_TRUE(s.ended);
  EXPECT_EQ(s.end_status, kExitUnstable);
  EXPECT_EQ(s.end_message, "unstable at step 12: J < 0 at particle 3");
  EXPECT_EQ(s.frames, 1u);
}

TEST(Stream, VisitorExceptionsPropagate) {
  TempDir d;
  const std::string p = d.file("run.mpm");
  {
    StreamWriter w(p);
    write_sample(w);
  }
  StreamVisitor v;
  v.frame = [](Frame&&) { throw InputError("post", "no column 'T'"); };
  EXPECT_THROW(read_stream(p, v), InputError);
}

TEST(Stream, Float32Precision) {
  TempDir d;
  const std::string p64 = d.file("f64.mpm"), p32 = d.file("f32.mpm");
  const Frame f = make_frame(5, 100);
  {
    StreamWriter w(p64);
    w.write_frame(f);
  }
  {
    StreamWriter w(p32);
    w.write_frame(f, {}, Precision::Float32);
  }
  // v, sigma and mass (10 f64 per element) shrink to f32; x, normal and the integers stay.
  EXPECT_EQ(fs::file_size(p64) - fs::file_size(p32), 100u * 10 * 4);
  Collected c;
  const StreamSummary s = read_stream(p32, c.visitor());
  EXPECT_EQ(s.damage, "");
  ASSERT_EQ(c.frames.size(), 1u);
  expect_frame(f, c.frames[0], Precision::Float32);
  // f32 rounding is visible, so the test above can tell the precisions apart.
  EXPECT_NE(get<double>(c.frames[0].columns.at("mass"), 1, 0),
            get<double>(f.columns.at("mass"), 1, 0));
  EXPECT_NE(double(float(get<double>(f.columns.at("x"), 1, 2))),
            get<double>(f.columns.at("x"), 1, 2));
  EXPECT_EQ(get<double>(c.frames[0].columns.at("x"), 1, 2), get<double>(f.columns.at("x"), 1, 2));
  // Out of the f32 range: infinite, not undefined; NaN stays NaN.
  Frame odd;
  odd.columns.add({"p", ScalarType::F64, 1, "Pa"});
  odd.columns.resize(4);
  const double in[4] = {1e300, -1e300, std::nan(""), 3.4e38};
  std::memcpy(odd.columns.at("p").data(), in, sizeof in);
  {
    StreamWriter w(p32);
    w.write_frame(odd, {}, Precision::Float32);
  }
  Collected co;
  read_stream(p32, co.visitor());
  ASSERT_EQ(co.frames.size(), 1u);
  const double* out = co.frames[0].columns.get<double>("p");
  EXPECT_EQ(out[0], HUGE_VAL);
  EXPECT_EQ(out[1], -HUGE_VAL);
  EXPECT_TRUE(std::isnan(out[2]));
  EXPECT_EQ(out[3], double(3.4e38f));
  // Large frames convert in several chunks.
  const Frame big = make_frame(6, 20000);
  {
    StreamWriter w(p32);
    w.write_frame(big, {"sigma", "x"}, Precision::Float32);
  }
  Collected cb;
  read_stream(p32, cb.visitor());
  ASSERT_EQ(cb.frames.size(), 1u);
  expect_frame(big, cb.frames[0], Precision::Float32, {"sigma", "x"});
}

TEST(Stream, FieldSelection) {
  TempDir d;
  const std::string p = d.file("sel.mpm");
  const Frame f = make_frame(1, 7);
  const std::vector<std::string> fields{"id", "x", "normal"};
  {
    StreamWriter w(p);
    w.write_frame(f, fields);
  }
  Collected c;
  read_stream(p, c.visitor());
  ASSERT_EQ(c.frames.size(), 1u);
  expect_frame(f, c.frames[0], Precision::Float64, fields);
  EXPECT_EQ(c.frames[0].columns.columns()[0].info().name, "id");  // the order given

  StreamWriter w(p);
  const std::uint64_t before = w.bytes_written();
  try {
    w.write_frame(f, {"x", "foo"});
    FAIL() << "unknown field accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(e.where(), "output.fields");
    EXPECT_EQ(
        e.message(),
        "unknown field 'foo' (available: x, v, sigma, mass, normal, material, id, cell, key)");
  }
  EXPECT_THROW(w.write_frame(f, {"x", "v", "x"}), InputError);
  EXPECT_EQ(w.bytes_written(), before) << "nothing is written for a bad selection";
  w.write_end(0, "");
  w.close();
  EXPECT_TRUE(read_stream(p, {}).ended);
}

TEST(Stream, RoundTripFifo) {
  TempDir d;
  const std::string p = d.file("fifo");
  ASSERT_EQ(mkfifo(p.c_str(), 0600), 0) << std::strerror(errno);
  // The writer waits after the first frame until the reader has it: this passes only if each
  // record is flushed when written. A large unknown record tests skipping in chunks on a pipe.
  std::mutex m;
  std::condition_variable cv;
  bool reader_has_first = false, waited_ok = false;
  std::vector<Frame> frames;
  frames.push_back(make_frame(0, 3, kFrameModel));
  frames.push_back(make_frame(10, 50000));
  frames.push_back(make_frame(20, 4, kFrameFinal));
  std::string writer_error;
  std::thread writer([&] {
    try {
      StreamWriter w(p);  // blocks until the reader opens the FIFO
      w.write_text(RecordType::Scene, kScene);
      w.write_frame(frames[0]);
      {
        std::unique_lock lock(m);
        waited_ok = cv.wait_for(lock, std::chrono::seconds(10), [&] { return reader_has_first; });
      }
      w.write_text(RecordType::Info, kInfo);
      w.write_frame(frames[1]);
      w.write_history(make_history(4));
      w.write_frame(frames[2]);
      w.write_end(0, "completed");
    } catch (const std::exception& e) {
      writer_error = e.what();
    }
  });
  Collected c;
  StreamVisitor v = c.visitor();
  v.frame = [&](Frame&& f) {
    c.frames.push_back(std::move(f));
    std::lock_guard lock(m);
    reader_has_first = true;
    cv.notify_all();
  };
  const StreamSummary s = read_stream(p, v);
  writer.join();
  EXPECT_EQ(writer_error, "");
  EXPECT_TRUE(waited_ok) << "the first frame did not reach the reader before the writer went on";
  expect_sample(c, s, frames);

  // Skipping a 3 MB record of a later minor version, then damage, on a pipe.
  std::thread raw([&] {
    Bytes b;
    {
      StreamWriter w(d.file("tmp.mpm"));
      w.write_text(RecordType::Scene, kScene);
    }
    b = slurp(d.file("tmp.mpm"));
    b += make_record("XTRA", Bytes(3 << 20, '\x5a'));
    b += make_record("INFO", kInfo, false);
    std::FILE* f = std::fopen(p.c_str(), "wb");
    std::fwrite(b.data(), 1, b.size(), f);
    std::fclose(f);
  });
  Collected c2;
  const StreamSummary s2 = read_stream(p, c2.visitor());
  raw.join();
  EXPECT_EQ(c2.scenes.size(), 1u);
  EXPECT_TRUE(c2.infos.empty());
  EXPECT_TRUE(
      contains(s2.damage, "record 3 (INFO at byte " +
                              std::to_string(16 + 12 + kScene.size() + 4 + 12 + (3 << 20) + 4) +
                              ") is corrupted (CRC mismatch); no frame precedes it"))
      << s2.damage;
}

TEST(Stream, StdinAndStdout) {
  TempDir d;
  const std::string p = d.file("std.mpm");
  std::vector<Frame> frames;
  // "-" writes to stdout and leaves it open.
  std::fflush(stdout);
  const int saved_out = dup(1);
  const int fd = ::open(p.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
  ASSERT_GE(fd, 0);
  dup2(fd, 1);
  ::close(fd);
  {
    StreamWriter w("-");
    frames = write_sample(w);
    EXPECT_EQ(w.path(), "-");
  }
  const bool stdout_open = std::fflush(stdout) == 0 && fcntl(1, F_GETFD) != -1;
  dup2(saved_out, 1);
  ::close(saved_out);
  EXPECT_TRUE(stdout_open);

  // "-" reads stdin and leaves it open.
  const int saved_in = dup(0);
  const int in = ::open(p.c_str(), O_RDONLY);
  ASSERT_GE(in, 0);
  dup2(in, 0);
  ::close(in);
  std::clearerr(stdin);
  Collected c;
  const StreamSummary s = read_stream("-", c.visitor());
  const bool stdin_open = fcntl(0, F_GETFD) != -1;
  dup2(saved_in, 0);
  ::close(saved_in);
  std::clearerr(stdin);
  EXPECT_TRUE(stdin_open);
  expect_sample(c, s, frames);
}

TEST(Stream, TruncationAtEveryByte) {
  TempDir d;
  const std::string full = d.file("full.mpm"), cut = d.file("cut.mpm");
  std::vector<Frame> frames;
  {
    StreamWriter w(full);
    frames = write_sample(w, 2);
  }
  const Bytes b = slurp(full);
  const Layout layout(b);
  ASSERT_EQ(layout.records.size(), 7u);
  std::set<std::size_t> boundaries{16};
  for (auto& r : layout.records) boundaries.insert(r.end);
  for (std::size_t n = 0; n <= b.size(); ++n) {
    SCOPED_TRACE("prefix of " + std::to_string(n) + " bytes");
    spit(cut, b.substr(0, n));
    Collected c;
    if (n < 16) {
      EXPECT_THROW(read_stream(cut, c.visitor()), StreamError);
      continue;
    }
    const StreamSummary s = read_stream(cut, c.visitor());
    const std::size_t want = layout.frames_before(n);
    ASSERT_EQ(s.frames, want);
    ASSERT_EQ(c.frames.size(), want);
    for (std::size_t i = 0; i < want; ++i) expect_frame(frames[i], c.frames[i]);
    EXPECT_EQ(s.ended, n == b.size());
    if (boundaries.count(n)) {
      ASSERT_EQ(s.damage, "");
    } else {
      const auto& rec = layout.record_at(n);
      const std::string label = cut + ": stream truncated in record " +
                                std::to_string(&rec - layout.records.data() + 1) + " (" +
                                (n - rec.begin < 4 ? "" : record_name(rec.type) + " ") +
                                "at byte " + std::to_string(rec.begin) + "): expected ";
      ASSERT_TRUE(contains(s.damage, label)) << s.damage;
      const std::string intact =
          want == 0   ? "no frame precedes it"
          : want == 1 ? "the 1 frame before it is intact"
                      : "the " + std::to_string(want) + " frames before it are intact";
      ASSERT_TRUE(contains(s.damage, "; " + intact)) << s.damage;
      const std::size_t payload = rec.end - rec.begin - 16;
      if (n < rec.begin + 12)
        EXPECT_TRUE(contains(
            s.damage, "expected a 12-byte record header, found " + std::to_string(n - rec.begin)));
      else if (n < rec.begin + 12 + payload)
        EXPECT_TRUE(contains(s.damage, "expected " + std::to_string(payload) +
                                           " payload bytes, found " +
                                           std::to_string(n - rec.begin - 12)))
            << s.damage;
      else
        EXPECT_TRUE(contains(s.damage,
                             "expected a 4-byte CRC, found " + std::to_string(n - (rec.end - 4))));
    }
  }
}

TEST(Stream, CorruptionOfEveryByte) {
  TempDir d;
  const std::string full = d.file("full.mpm"), bad = d.file("bad.mpm");
  std::vector<Frame> frames;
  {
    StreamWriter w(full);
    frames = write_sample(w, 2);
  }
  const Bytes b = slurp(full);
  const Layout layout(b);
  for (unsigned char mask : {0x01, 0x80, 0xFF}) {
    for (std::size_t at = 16; at < b.size(); ++at) {
      SCOPED_TRACE("byte " + std::to_string(at) + " xor " + std::to_string(mask));
      Bytes m = b;
      m[at] = char(m[at] ^ mask);
      spit(bad, m);
      Collected c;
      const StreamSummary s = read_stream(bad, c.visitor());
      const auto& rec = layout.record_at(at);
      const std::size_t want = layout.frames_before(rec.begin);
      ASSERT_NE(s.damage, "");
      ASSERT_FALSE(s.ended);
      ASSERT_EQ(s.frames, want);
      ASSERT_EQ(c.frames.size(), want);
      for (std::size_t i = 0; i < want; ++i) expect_frame(frames[i], c.frames[i]);
      const std::string record =
          "record " + std::to_string(&rec - layout.records.data() + 1) + " (";
      ASSERT_TRUE(contains(s.damage, record)) << s.damage;
      const bool in_length = at >= rec.begin + 4 && at < rec.begin + 12;
      // A changed length may look like truncation, except in a frame, whose column table
      // gives its length; anything else is reported as corruption.
      if (!in_length || rec.type == std::uint32_t(RecordType::Frame))
        ASSERT_TRUE(contains(s.damage, ") is corrupted (")) << s.damage;
      else
        ASSERT_TRUE(contains(s.damage, ") is corrupted (") || contains(s.damage, "truncated"))
            << s.damage;
    }
  }
}

TEST(Stream, StreamHeaderDamage) {
  TempDir d;
  const std::string full = d.file("full.mpm"), bad = d.file("bad.mpm");
  {
    StreamWriter w(full);
    write_sample(w, 2);
  }
  const Bytes b = slurp(full);
  for (std::size_t at = 0; at < 16; ++at) {
    Bytes m = b;
    m[at] = char(m[at] ^ 0x04);
    spit(bad, m);
    if (at < 10) {
      EXPECT_THROW(read_stream(bad, {}), StreamError) << "byte " << at;
    } else {  // minor version and reserved word: accepted
      const StreamSummary s = read_stream(bad, {});
      EXPECT_TRUE(s.ended) << "byte " << at;
      EXPECT_EQ(s.damage, "");
    }
  }
}

std::string header_error(const std::string& path) {
  try {
    StreamReader r(path);
  } catch (const StreamError& e) {
    return e.what();
  }
  return "(accepted)";
}

TEST(Stream, BadHeaders) {
  TempDir d;
  const std::string p = d.file("in.mpm");
  spit(p, Bytes("\x7f"
                "ELF\x02\x01\x01\x00\x00\x00\x00\x00\x00\x00\x00\x00",
                16));
  EXPECT_EQ(header_error(p), p + ": not an mpm stream (bad magic)");

  spit(p, "# Taylor bar\n[scene]\nname = \"taylor\"\n");
  EXPECT_EQ(header_error(p), p + ": not an mpm stream (bad magic); this looks like a scene file; "
                                 "run mpm-prep on it first");
  spit(p, "[scene]\n");  // shorter than a header
  EXPECT_TRUE(contains(header_error(p), "run mpm-prep on it first"));
  spit(p, "end_time = 1e-5\n");
  EXPECT_TRUE(contains(header_error(p), "run mpm-prep on it first"));

  spit(p, Bytes("\x89MPM\n\x1a\n\x01\x00\x00\x00\x00\x00\x00\x00\x00", 16));  // CRLF -> LF
  EXPECT_TRUE(contains(header_error(p), "bad magic); its line endings were converted"))
      << header_error(p);

  spit(p, "");
  EXPECT_TRUE(contains(header_error(p), "empty input")) << header_error(p);
  spit(p, Bytes("\x89MPM\r\n\x1a\n\x01\x00", 10));
  EXPECT_EQ(header_error(p), p + ": stream truncated in its header: expected 16 bytes, found 10");
  EXPECT_TRUE(contains(header_error(d.file("missing.mpm")), "cannot open: No such file"));

  Bytes future("\x89MPM\r\n\x1a\n\x02\x00\x00\x00\x00\x00\x00\x00", 16);
  spit(p, future);
  EXPECT_EQ(header_error(p), p + ": written by a newer mpm (format 2.x); this reader knows 1.x");
  EXPECT_THROW(read_stream(p, {}), StreamError);

  // A newer minor version is read, and its unknown record types are skipped.
  Bytes minor("\x89MPM\r\n\x1a\n\x01\x00\x07\x00\x00\x00\x00\x00", 16);
  spit(p, minor + make_record("ENDS", Bytes(4, '\0')));
  EXPECT_TRUE(read_stream(p, {}).ended);
}

TEST(Stream, UnknownRecordTypes) {
  TempDir d;
  const std::string full = d.file("full.mpm"), p = d.file("x.mpm");
  std::vector<Frame> frames;
  {
    StreamWriter w(full);
    frames = write_sample(w, 2);
  }
  const Bytes b = slurp(full);
  const Layout layout(b);
  const std::size_t after_first_frame = layout.records[2].end;
  auto splice = [&](const Bytes& rec) {
    return b.substr(0, after_first_frame) + rec + b.substr(after_first_frame);
  };

  // A valid record of an unknown type is skipped; everything else arrives.
  spit(p, splice(make_record("XTRA", "payload of a later minor version")));
  Collected c;
  expect_sample(c, read_stream(p, c.visitor()), frames);
  spit(p, splice(make_record("XTR0", "")));
  Collected c0;
  expect_sample(c0, read_stream(p, c0.visitor()), frames);

  // With a bad CRC it is corruption.
  spit(p, splice(make_record("XTRA", "payload", false)));
  Collected c1;
  StreamSummary s = read_stream(p, c1.visitor());
  EXPECT_EQ(s.damage, p + ": record 4 (?XTRA at byte " + std::to_string(after_first_frame) +
                          ") is corrupted (CRC mismatch); the 1 frame before it is intact");
  EXPECT_EQ(c1.frames.size(), 1u);

  // A type code outside [A-Z0-9_] is corruption even with a valid CRC.
  spit(p, splice(make_record("xtra", "payload")));
  s = read_stream(p, {});
  EXPECT_TRUE(contains(s.damage, "record 4 (?0x61727478 at byte " +
                                     std::to_string(after_first_frame) +
                                     ") is corrupted (invalid record type)"))
      << s.damage;

  // An implausible length is corruption at once (not a 16 TB read).
  Bytes huge = make_record("XTRA", "");
  const std::uint64_t len = (std::uint64_t(1) << 44) + 1;
  std::memcpy(huge.data() + 4, &len, 8);
  spit(p, splice(huge));
  s = read_stream(p, {});
  EXPECT_TRUE(contains(s.damage, "is corrupted (implausible payload length 17592186044417)"))
      << s.damage;
  EXPECT_EQ(s.frames, 1u);

  // Malformed payloads with a valid CRC are corruption too.
  spit(p, splice(make_record(
              "HIST",
              Bytes("\x01\x00\x00\x00\x01\x00t\x01\x00s\x05\x00\x00\x00\x00\x00\x00\x00", 18))));
  s = read_stream(p, {});
  EXPECT_EQ(s.damage, "");  // no history callback: not decoded
  Collected c2;
  s = read_stream(p, c2.visitor());
  EXPECT_TRUE(contains(
      s.damage,
      "record 4 (HIST at byte " + std::to_string(after_first_frame) +
          ") is corrupted (malformed HIST payload: 5 rows of 1 values need 40 bytes, 0 are left)"))
      << s.damage;
  spit(p, splice(make_record("ENDS", "ab")));
  s = read_stream(p, {});
  EXPECT_TRUE(contains(s.damage, "is corrupted (malformed ENDS payload")) << s.damage;
  EXPECT_FALSE(s.ended);
}

TEST(Stream, FrameTableChecks) {
  // Frames whose CRC is valid but whose column table disagrees with the record length, or
  // holds an unknown scalar type, are corruption; a huge element count allocates nothing.
  TempDir d;
  const std::string full = d.file("full.mpm"), p = d.file("f.mpm");
  {
    StreamWriter w(full);
    w.write_frame(make_frame(3, 2));
  }
  const Bytes b = slurp(full);
  const Layout layout(b);
  const Bytes payload = b.substr(16 + 12, layout.records[0].end - 16 - 16);
  auto with = [&](std::size_t at, const void* v, std::size_t n) {
    Bytes m = payload;
    std::memcpy(m.data() + at, v, n);
    spit(p, b.substr(0, 16) + make_record("FRAM", m));
    Collected c;
    const StreamSummary s = read_stream(p, c.visitor());
    EXPECT_TRUE(c.frames.empty());
    return s.damage;
  };
  spit(p, b.substr(0, 16) + make_record("FRAM", payload));
  Collected ok;
  EXPECT_EQ(read_stream(p, ok.visitor()).damage, "");
  ASSERT_EQ(ok.frames.size(), 1u);
  expect_frame(make_frame(3, 2), ok.frames[0]);

  const std::uint64_t n1 = 1, n3 = 3, huge = std::uint64_t(1) << 62;
  EXPECT_EQ(with(20, &n1, 8),
            p + ": record 1 (FRAM at byte 16) is corrupted (its length " +
                std::to_string(payload.size()) + " disagrees with its column table (" +
                std::to_string(payload.size() - 157) + " bytes)); no frame precedes it");
  EXPECT_TRUE(contains(with(20, &n3, 8),
                       "is corrupted (its column table needs more bytes than its length of "));
  EXPECT_TRUE(contains(with(20, &huge, 8),
                       "is corrupted (its column table needs more bytes than its length of "));
  const std::uint8_t bad_type = 9;  // the type code of "x": after 32 fixed bytes, u16 1, "x"
  EXPECT_TRUE(
      contains(with(32 + 3, &bad_type, 1), "is corrupted (column 1 has unknown scalar type 9)"));
  const std::uint8_t zero = 0;
  EXPECT_TRUE(contains(with(32 + 4, &zero, 1), "is corrupted (column 'x' has 0 components)"));
  const std::uint32_t many = 1000000;
  EXPECT_TRUE(contains(with(28, &many, 4), "is corrupted (its content runs past its length of "));
  spit(p, b.substr(0, 16) + make_record("FRAM", payload.substr(0, 20)));
  StreamVisitor frames_only;
  frames_only.frame = [](Frame&&) {};
  EXPECT_TRUE(contains(read_stream(p, frames_only).damage,
                       "is corrupted (a frame needs at least 32 bytes, it has 20)"));
}

TEST(Stream, ReaderStaysFailed) {
  TempDir d;
  const std::string full = d.file("full.mpm");
  {
    StreamWriter w(full);
    write_sample(w, 2);
  }
  Bytes b = slurp(full);
  const Layout layout(b);
  b[layout.records[0].begin + 14] ^= 1;  // in the SCEN payload
  spit(full, b);
  StreamReader r(full);
  std::uint32_t type;
  ASSERT_TRUE(r.next(type));
  try {
    r.read_payload();
    FAIL() << "corruption not detected";
  } catch (const StreamError& e) {
    EXPECT_EQ(
        std::string(e.what()),
        full + ": record 1 (SCEN at byte 16) is corrupted (CRC mismatch); no frame precedes it");
  }
  EXPECT_THROW(r.next(type), StreamError);
}

TEST(Stream, WriteFailures) {
  // Disk full: the header write is flushed at once and fails.
  try {
    StreamWriter w("/dev/full");
    FAIL() << "writing to /dev/full succeeded";
  } catch (const IoError& e) {
    EXPECT_EQ(std::string(e.what()), "/dev/full: write failed: No space left on device");
  }
  TempDir d;
  EXPECT_THROW(StreamWriter(d.file("no/such/dir.mpm")), IoError);

  // The reader of a pipe went away: EPIPE (SIGPIPE ignored, as the tools do).
  int fds[2];
  ASSERT_EQ(pipe(fds), 0);
  auto old = std::signal(SIGPIPE, SIG_IGN);
  const std::string path = "/dev/fd/" + std::to_string(fds[1]);
  {
    StreamWriter w(path);
    ::close(fds[1]);
    ::close(fds[0]);
    try {
      w.write_frame(make_frame(0, 10));
      FAIL() << "writing to a closed pipe succeeded";
    } catch (const IoError& e) {
      EXPECT_EQ(std::string(e.what()), path + ": write failed: Broken pipe");
    }
    try {
      w.write_end(0, "");
      FAIL() << "a write after a failed one succeeded";
    } catch (const IoError& e) {
      EXPECT_EQ(std::string(e.what()), path + ": an earlier write failed; nothing more is written");
    }
  }
  std::signal(SIGPIPE, old);

  // Writing after close() is refused.
  StreamWriter w(d.file("closed.mpm"));
  w.close();
  EXPECT_THROW(w.write_end(0, ""), IoError);
}

}  // namespace
}  // namespace mpm
