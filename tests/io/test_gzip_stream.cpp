// gzip input is parsed as it is inflated (src/io/byte_source.h): the header is checked after the
// first bytes, consumed bytes are dropped, and inflation is capped. The bombs are issue 12's:
// each must end within the watchdog with one line naming the file, in under 300 MB.
#include "byte_source.h"
#include "io_internal.h"
#include "test_support.h"
#include "vertexflow/io.h"

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <zlib.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <string>
#include <vector>

namespace vertexflow {
namespace {

namespace fs = std::filesystem;
using test::ScratchDir;

// One gzip member of `data` (windowBits 31: gzip wrapper). Members concatenate to one stream,
// so a bomb is one member repeated.
std::string gzip_member(std::string_view data, int level = 9) {
  z_stream z{};
  EXPECT_EQ(deflateInit2(&z, level, Z_DEFLATED, 31, 9, Z_DEFAULT_STRATEGY), Z_OK);
  std::string out(deflateBound(&z, data.size()), '\0');
  z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(data.data()));
  z.avail_in = static_cast<uInt>(data.size());
  z.next_out = reinterpret_cast<Bytef*>(out.data());
  z.avail_out = static_cast<uInt>(out.size());
  EXPECT_EQ(deflate(&z, Z_FINISH), Z_STREAM_END);
  out.resize(z.total_out);
  deflateEnd(&z);
  return out;
}

void write_file(const fs::path& path, const std::string& first, const std::string& repeated, int times) {
  std::ofstream out(path, std::ios::binary);
  out << first;
  for (int i = 0; i < times; ++i) out << repeated;
}

std::string ply_header(std::int64_t vertices) {
  return "ply\nformat ascii 1.0\nelement vertex " + std::to_string(vertices) +
         "\nproperty float x\nproperty float y\nproperty float z\nelement face 1\n"
         "property list uchar int vertex_indices\nend_header\n";
}

// 16 MiB of vertex lines, compressed once (about 32 kB).
const std::string& vertex_lines_member() {
  static const std::string member = [] {
    std::string lines;
    for (std::size_t i = 0; i < (std::size_t{16} << 20) / 12; ++i) lines += "0.5 0.5 0.5\n";
    return gzip_member(lines);
  }();
  return member;
}

// Peak RSS of `vertexflow info` on each bomb, measured when this test was written: 63 MB
// (zeros), 192 MB (vertex lines), 61 MB (trailing), of which about 60 MB is the CLI itself
// (its libraries). The bar is the 300 MB; the old reader reached 10-11 GB.
constexpr long kMaxRssKb = 300 * 1024;
// A hang guard, not a speed check (the runs took 0.2-1.7 s).
constexpr double kWatchdogSeconds = 120;

void expect_one_line_error(const test::WatchedRun& run, const fs::path& file, const std::string& fragment) {
  EXPECT_FALSE(run.timed_out) << "watchdog: still running after " << kWatchdogSeconds << " s";
  EXPECT_EQ(run.exit_code, 1) << run.err;
  EXPECT_EQ(std::count(run.err.begin(), run.err.end(), '\n'), 1) << run.err;
  EXPECT_NE(run.err.find(file.string() + ": "), std::string::npos) << run.err;
  EXPECT_NE(run.err.find(fragment), std::string::npos) << run.err;
#ifndef VERTEXFLOW_TEST_ASAN  // its shadow memory and quarantine add 100-200 MB (384 MB measured)
  EXPECT_LT(run.peak_rss_kb, kMaxRssKb) << run.err;
#endif
}

TEST(GzipBomb, FiveGigabytesOfZerosFailAtTheHeader) {
  const ScratchDir scratch("bomb-zeros");
  const fs::path bomb = scratch.file("zeros.ply.gz");
  write_file(bomb, "", gzip_member(std::string(std::size_t{64} << 20, '\0')), 80);  // 5 GiB, 5.2 MB
  const auto run = test::run_cli_watched({"info", bomb.string()}, kWatchdogSeconds);
  expect_one_line_error(run, bomb, "not a PLY file");
}

TEST(GzipBomb, AValidHeaderAndAGigabyteOfVertexLinesStopAtTheLimit) {
  const ScratchDir scratch("bomb-lines");
  const fs::path bomb = scratch.file("lines.ply.gz");
  // The header's 10 million vertices fit the limit's bytes; the lines run past it.
  write_file(bomb, gzip_member(ply_header(10'000'000)), vertex_lines_member(), 64);  // 1 GiB, 2.1 MB
  const auto run = test::run_cli_watched({"info", bomb.string()}, kWatchdogSeconds);
  expect_one_line_error(run, bomb, "gzip data inflates to more than 67108864 bytes");
  EXPECT_NE(run.err.find("VERTEXFLOW_MAX_INFLATE_RATIO"), std::string::npos) << run.err;

  // The environment variable moves the limit: 40 x 2.1 MB is above the 64 MiB floor.
  const auto raised =
      test::run_cli_watched({"info", bomb.string()}, kWatchdogSeconds, {"VERTEXFLOW_MAX_INFLATE_RATIO=40"});
  const auto compressed = fs::file_size(bomb);
  expect_one_line_error(raised, bomb,
                        "inflates to more than " + std::to_string(40 * compressed) + " bytes, the limit for " +
                            std::to_string(compressed) + " compressed bytes (40 times as many");
}

TEST(GzipBomb, AHeaderClaimingMoreThanTheLimitCanHoldFailsAtTheHeader) {
  const ScratchDir scratch("bomb-claim");
  const fs::path bomb = scratch.file("claim.ply.gz");
  write_file(bomb, gzip_member(ply_header(1'000'000'000)), vertex_lines_member(), 64);
  const auto run = test::run_cli_watched({"info", bomb.string()}, kWatchdogSeconds);
  expect_one_line_error(run, bomb, "(the gzip inflation limit) can hold at most");
}

TEST(GzipBomb, AGigabyteAfterAValidMeshIsStillABomb) {
  const ScratchDir scratch("bomb-trailing");
  const fs::path bomb = scratch.file("trailing.ply.gz");
  // A complete one-triangle mesh; the parser needs only its first member, but the stream is
  // checked to its end (ByteSource::verify_rest), within the limit and in constant memory.
  write_file(bomb, gzip_member(ply_header(3) + "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"), vertex_lines_member(), 64);
  const auto run = test::run_cli_watched({"info", bomb.string()}, kWatchdogSeconds);
  expect_one_line_error(run, bomb, "gzip data inflates to more than");
}

TEST(GzipBomb, AnEndlessContinuedObjLineStopsAtTheLimit) {
  const ScratchDir scratch("bomb-continued");
  const fs::path bomb = scratch.file("continued.obj.gz");
  // One `f` statement continued over a gigabyte of lines: joined as it is read, never held.
  const std::string continuations = gzip_member([] {
    std::string lines;
    for (std::size_t i = 0; i < (std::size_t{16} << 20) / 2; ++i) lines += "\\\n";
    return lines;
  }());
  write_file(bomb, gzip_member("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3 \\\n"), continuations, 64);  // 1 GiB
  const auto run = test::run_cli_watched({"info", bomb.string()}, kWatchdogSeconds);
  expect_one_line_error(run, bomb, "gzip data inflates to more than 67108864 bytes");
}

// --- streaming -------------------------------------------------------------------------------

// An OBJ text of `n` vertex lines of varied length and faces over them.
std::string obj_text(int n) {
  std::string text;
  for (int i = 0; i < n; ++i)
    text += "v " + std::to_string(i % 1000) + " " + std::to_string(i / 1000) + ".125 " + std::to_string(i % 7) + "\n";
  for (int i = 0; i + 1001 < n; i += 3) {
    text += "f " + std::to_string(i + 1) + " " + std::to_string(i + 2) + " " + std::to_string(i + 1001) + "\n";
  }
  return text;
}

TEST(GzipStream, TheWindowStaysSmallWhileTheParserStreams) {
  const std::string text = obj_text(1'000'000);  // about 24 MB
  const std::string compressed = gzip_member(text, 1);
  const std::string name = "big.obj.gz";
  io_detail::ByteSource source(compressed, name, {});
  io_detail::TextScanner in(source, name);
  std::size_t largest_window = 0, tokens = 0;
  while (!in.token().empty()) {
    ++tokens;
    largest_window = std::max(largest_window, source.data().size());
  }
  EXPECT_EQ(in.position(), text.size());
  EXPECT_GT(tokens, 4'000'000u);
  // Without dropping consumed bytes the window would be the whole 24 MB; with it, the first
  // chunk (256 kB) is reused.
  EXPECT_LE(largest_window, std::size_t{1} << 20) << "of " << text.size() << " bytes";
}

TEST(GzipStream, ReadsTheSameMeshAsThePlainFileForEveryFormat) {
  for (const char* name : {"armadillo-43k.obj", "amo.off", "horse-48k.ply", "icosahedron_ascii.stl",
                           "icosahedron_binary.stl", "fandisk_quads.off"}) {
    SCOPED_TRACE(name);
    const fs::path path = test::data_path(name);
    const std::string bytes = test::read_text(path);
    const MeshFormat format = format_from_path(path);
    const Mesh plain = read_mesh_from_memory(bytes, format, name);
    const Mesh inflated = read_mesh_from_memory(gzip_member(bytes, 6), format, name);
    EXPECT_EQ(plain.V, inflated.V);
    EXPECT_EQ(plain.F, inflated.F);
  }
}

// Reading `text` as OBJ, plain and as one gzip member, fails with an error containing `expected`.
void expect_obj_error_plain_and_gzipped(const std::string& text, const std::string& expected) {
  for (const bool gzip : {false, true}) {
    SCOPED_TRACE(gzip ? "gzip" : "plain");
    try {
      read_mesh_from_memory(gzip ? gzip_member(text, 1) : text, MeshFormat::Obj, "bad.obj");
      ADD_FAILURE() << "accepted";
    } catch (const IoError& e) {
      EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
    }
  }
}

TEST(GzipStream, LineNumbersCountTheDroppedBytes) {
  // Far past the first chunks, so the line number includes newlines that were dropped.
  std::string text = obj_text(400'000);
  const auto lines = std::count(text.begin(), text.end(), '\n');
  text += "v 1 2 x\n";
  const std::string expected = "line " + std::to_string(lines + 1) + ": expected a vertex coordinate, found 'x'";
  expect_obj_error_plain_and_gzipped(text, expected);
}

TEST(GzipStream, AContinuedStatementsErrorNamesItsFirstLineAfterDroppedBytes) {
  // The statement starts far into the stream and spans more lines than a window holds, so
  // both its first line and the bad index's line lie in dropped bytes.
  std::string text = obj_text(400'000);
  const auto lines = std::count(text.begin(), text.end(), '\n');
  text += "f 1 2 \\\n";
  for (int i = 0; i < 1'000'000; ++i) text += "3 \\\n";
  text += "x\n";
  const std::string expected = "line " + std::to_string(lines + 1) + ": expected a face vertex index, found 'x'";
  expect_obj_error_plain_and_gzipped(text, expected);
}

TEST(GzipStream, ATruncatedStreamIsAnErrorEvenAfterACompleteMesh) {
  const std::string mesh = ply_header(3) + "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
  const std::string padded = mesh + std::string(1 << 20, '\n');  // trailing bytes the parser never needs
  std::string compressed = gzip_member(padded);
  compressed.resize(compressed.size() - 6);  // cut into the CRC/size trailer
  try {
    read_mesh_from_memory(compressed, MeshFormat::Ply, "cut.ply.gz");
    ADD_FAILURE() << "accepted";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find("cut.ply.gz: truncated gzip data"), std::string::npos) << e.what();
  }
  EXPECT_EQ(read_mesh_from_memory(gzip_member(padded), MeshFormat::Ply, "whole.ply.gz").num_faces(), 1);
}

// --- the format from the content -------------------------------------------------------------

TEST(FormatFromContent, APlyFileNamedObjIsReadAsPly) {
  const std::string ply = test::read_text(test::data_path("horse-48k.ply"));
  ReadReport report;
  const Mesh mesh = read_mesh_from_memory(ply, MeshFormat::Obj, "horse.obj", &report);
  EXPECT_EQ(report.format, MeshFormat::Ply);
  EXPECT_TRUE(report.format_differs_from_extension);
  EXPECT_EQ(mesh.F, read_mesh(test::data_path("horse-48k.ply")).F);
  ASSERT_FALSE(report.warnings().empty());
  EXPECT_NE(report.warnings().front().find("content is PLY"), std::string::npos) << report.warnings().front();
}

TEST(FormatFromContent, ABinaryStlWithASolidCommentAndATrailingByteIsBinary) {
  std::string stl = test::read_text(test::data_path("icosahedron_binary.stl"));
  stl.replace(0, 5, "solid");
  stl += '\n';
  ReadReport report;
  const Mesh mesh = read_mesh_from_memory(stl, MeshFormat::Stl, "ico.stl", &report);
  EXPECT_TRUE(report.binary);
  EXPECT_EQ(mesh.num_faces(), 20);
  EXPECT_EQ(mesh.num_vertices(), 12);
}

TEST(FormatFromContent, AnOffFileNamedPlyIsReadAsOff) {
  const std::string off = test::read_text(test::data_path("fandisk.off"));
  ReadReport report;
  const Mesh mesh = read_mesh_from_memory(off, MeshFormat::Ply, "fandisk.ply", &report);
  EXPECT_EQ(report.format, MeshFormat::Off);
  EXPECT_EQ(mesh.F, read_mesh(test::data_path("fandisk.off")).F);
}

TEST(FormatFromContent, BinaryDataNamedObjFailsAtOnce) {
  try {
    read_mesh_from_memory(std::string(1 << 20, '\0'), MeshFormat::Obj, "zeros.obj");
    ADD_FAILURE() << "accepted";
  } catch (const IoError& e) {
    EXPECT_STREQ(e.what(), "zeros.obj: not an OBJ file (it holds binary data, and OBJ is text)");
  }
}

// A PLY of an n x n grid (two triangles per square): x, y, z as `vertex_type`, then, with
// `extra`, a float normal, uchar colours and a float "quality"; faces as one-byte counts and
// 4-byte indices (`index_type` "int" or "uint"), with `quads` squares instead of triangles and
// `bad` (face, corner, index) written over the grid's. Binary (little or big endian), or ASCII
// with every value exact (%.17g of the value the binary file holds).
enum class PlyEncoding { Little, Big, Ascii };
std::string grid_ply(int n, PlyEncoding encoding, const std::string& vertex_type, bool extra,
                     const std::string& index_type, bool quads,
                     const std::vector<std::array<std::int64_t, 3>>& bad = {}) {
  std::string out;
  auto put = [&](auto value) {
    if (encoding == PlyEncoding::Ascii) {
      out += fmt::format("{:.17g} ", static_cast<double>(value));
      return;
    }
    char bytes[sizeof value];
    std::memcpy(bytes, &value, sizeof value);
    if (encoding == PlyEncoding::Big) std::reverse(bytes, bytes + sizeof value);
    out.append(bytes, sizeof value);
  };
  auto end_line = [&] {
    if (encoding == PlyEncoding::Ascii) out.back() = '\n';
  };
  std::vector<std::vector<std::int64_t>> faces;
  for (int i = 0; i + 1 < n; ++i)
    for (int j = 0; j + 1 < n; ++j) {
      const std::int64_t a = i * n + j, b = a + n, c = b + 1, d = a + 1;
      if (quads)
        faces.push_back({a, b, c, d});
      else
        faces.push_back({a, b, c}), faces.push_back({a, c, d});
    }
  for (const auto& [f, k, index] : bad) faces[static_cast<std::size_t>(f)][static_cast<std::size_t>(k)] = index;
  const char* format = encoding == PlyEncoding::Ascii ? "ascii"
                       : encoding == PlyEncoding::Big ? "binary_big_endian"
                                                      : "binary_little_endian";
  out = fmt::format("ply\nformat {} 1.0\nelement vertex {}\nproperty {} x\nproperty {} y\nproperty {} z\n", format,
                    n * n, vertex_type, vertex_type, vertex_type);
  if (extra)
    out +=
        "property float nx\nproperty float ny\nproperty float nz\nproperty uchar red\nproperty uchar "
        "green\nproperty uchar blue\nproperty float quality\n";
  out += fmt::format("element face {}\nproperty list uchar {} vertex_indices\nend_header\n", faces.size(), index_type);
  for (int v = 0; v < n * n; ++v) {
    const double x = v / n, y = v % n, z = 0.3 * std::sin(0.3 * x) * std::cos(0.2 * y) + 1e-9 * v;
    for (const double c : {x, y, z}) vertex_type == "double" ? put(c) : put(static_cast<float>(c));
    if (extra) {
      for (const float c : {0.0f, 0.6f, 0.8f}) put(c);
      for (const int c : {v % 256, (7 * v) % 256, (13 * v) % 256}) put(static_cast<std::uint8_t>(c));
      put(0.25f * static_cast<float>(v));
    }
    end_line();
  }
  for (const auto& face : faces) {
    put(static_cast<std::uint8_t>(face.size()));
    for (const std::int64_t index : face)
      index_type == "uint" ? put(static_cast<std::uint32_t>(index)) : put(static_cast<std::int32_t>(index));
    end_line();
  }
  return out;
}

void expect_same_mesh(const Mesh& a, const Mesh& b, const fs::path& file) {
  EXPECT_EQ(a.V, b.V) << file;
  EXPECT_EQ(a.F, b.F) << file;
  ASSERT_EQ(a.attributes.vertex.size(), b.attributes.vertex.size()) << file;
  for (std::size_t c = 0; c < a.attributes.vertex.size(); ++c) {
    EXPECT_EQ(a.attributes.vertex[c].name, b.attributes.vertex[c].name) << file;
    EXPECT_EQ(a.attributes.vertex[c].components, b.attributes.vertex[c].components) << file;
    EXPECT_EQ(a.attributes.vertex[c].values, b.attributes.vertex[c].values) << file;
  }
}

std::string read_error(const fs::path& file) {
  try {
    read_mesh(file);
  } catch (const IoError& e) {
    return e.what();
  }
  return "";
}

// Binary records are decoded on all threads at once when the whole file is in memory (read_ply.cpp:
// fixed-size vertex records, triangle records). They must give what the value-by-value read of
// the same values in ASCII gives, and the same error for the same bad index: the first face's.
TEST(BinaryPly, RecordsDecodedAtOnceReadAsTheAsciiValues) {
  const ScratchDir scratch("binary-ply");
  int case_number = 0;
  for (const std::string vertex_type : {"float", "double"})
    for (const bool extra : {false, true})
      for (const std::string index_type : {"int", "uint"})
        for (const bool quads : {false, true}) {
          const fs::path ascii = scratch.file("grid" + std::to_string(case_number) + "_ascii.ply");
          std::ofstream(ascii, std::ios::binary)
              << grid_ply(60, PlyEncoding::Ascii, vertex_type, extra, index_type, quads);
          const Mesh expected = read_mesh(ascii);
          EXPECT_EQ(expected.num_faces(), 2 * 59 * 59) << ascii;
          EXPECT_EQ(expected.attributes.vertex.size(), extra ? 3u : 0u) << ascii;  // normal, color, quality
          for (const PlyEncoding encoding : {PlyEncoding::Little, PlyEncoding::Big}) {
            const fs::path binary = scratch.file("grid" + std::to_string(case_number) +
                                                 (encoding == PlyEncoding::Big ? "_big.ply" : "_little.ply"));
            std::ofstream(binary, std::ios::binary) << grid_ply(60, encoding, vertex_type, extra, index_type, quads);
            expect_same_mesh(read_mesh(binary), expected, binary);
          }
          ++case_number;
        }
  // Bad indices in faces 3000, 300 and 6000 (negative, and past the vertices): each read names
  // face 300; as a uint, -9 is 4294967287, above 2^31 - 1.
  const std::vector<std::array<std::int64_t, 3>> bad = {{3000, 0, -3}, {300, 2, -9}, {6000, 1, 6000}};
  for (const std::string index_type : {"int", "uint"}) {
    const fs::path ascii = scratch.file("bad_" + index_type + "_ascii.ply");
    const fs::path binary = scratch.file("bad_" + index_type + ".ply");
    std::ofstream(ascii, std::ios::binary) << grid_ply(60, PlyEncoding::Ascii, "float", false, "int", false, bad);
    std::ofstream(binary, std::ios::binary)
        << grid_ply(60, PlyEncoding::Little, "float", false, index_type, false, bad);
    const std::string error = read_error(binary);
    EXPECT_NE(
        error.find(fmt::format("face 300 has invalid vertex index {}", index_type == "int" ? "-9" : "4294967287")),
        std::string::npos)
        << error;
    if (index_type == "int")
      EXPECT_EQ(error.substr(error.find(": ")), read_error(ascii).substr(read_error(ascii).find(": ")));
  }
}

}  // namespace
}  // namespace vertexflow
