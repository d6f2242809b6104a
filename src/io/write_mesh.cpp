// Writers for OBJ, PLY, OFF and STL, optionally gzip-compressed, with atomic replacement:
// bytes go to a temporary file beside the target, which is renamed over it only when complete.
#include "io_internal.h"

#include <zlib.h>

#include <fmt/format.h>

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <random>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

namespace vertexflow {
namespace io_detail {
namespace {

// A temporary file in the target's directory; commit() renames it into place, the destructor
// removes it if commit() was not reached (an exception, a full disk).
class AtomicFile {
 public:
  explicit AtomicFile(std::filesystem::path target) : target_(std::move(target)) {
    const std::filesystem::path dir = target_.has_parent_path() ? target_.parent_path() : ".";
    // Hidden name beside the target, so the rename stays on one file system. Created with mode
    // 0666 so the process's umask gives the file its usual permissions (mkstemp would give
    // 0600); O_EXCL with a random suffix makes the name ours.
    std::random_device random;
    for (int attempt = 0; attempt < 100 && fd_ < 0; ++attempt) {
      std::string hidden = ".";
      hidden += target_.filename().string();
      hidden += ".tmp-";
      hidden += std::to_string(random());
      temp_ = (dir / hidden).string();
      fd_ = ::open(temp_.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
      if (fd_ < 0 && errno != EEXIST) break;
    }
    if (fd_ < 0) {
      committed_ = true;  // nothing to remove
      fail(target_.string(), std::string("cannot create a temporary file beside it: ") + std::strerror(errno));
    }
  }
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;
  ~AtomicFile() {
    if (fd_ >= 0) ::close(fd_);
    if (!committed_) ::unlink(temp_.c_str());
  }

  void write(const char* data, std::size_t size) {
    while (size > 0) {
      const ssize_t n = ::write(fd_, data, size);
      if (n < 0) {
        if (errno == EINTR) continue;
        fail(target_.string(), std::string("write error: ") + std::strerror(errno));
      }
      data += n;
      size -= static_cast<std::size_t>(n);
    }
  }

  void commit() {
    // Data on disk before the rename.
    if (::fsync(fd_) != 0) fail(target_.string(), std::string("cannot flush: ") + std::strerror(errno));
    if (::close(fd_) != 0) {
      fd_ = -1;
      fail(target_.string(), std::string("cannot close: ") + std::strerror(errno));
    }
    fd_ = -1;
    if (::rename(temp_.c_str(), target_.c_str()) != 0)
      fail(target_.string(), std::string("cannot rename the temporary file into place: ") + std::strerror(errno));
    committed_ = true;
  }

 private:
  std::filesystem::path target_;
  std::string temp_;
  int fd_ = -1;
  bool committed_ = false;
};

// Buffers output and passes it to the file, deflating it first for ".gz" targets.
class Output {
 public:
  Output(const std::filesystem::path& path, bool gzip) : file_(path), gzip_(gzip), name_(path.string()) {
    if (gzip_ && deflateInit2(&stream_, Z_DEFAULT_COMPRESSION, Z_DEFLATED, 16 + MAX_WBITS, 8, Z_DEFAULT_STRATEGY) != Z_OK)
      fail(name_, "cannot initialise gzip encoder");
    buffer_.reserve(kChunk + 4096);
  }
  Output(const Output&) = delete;
  Output& operator=(const Output&) = delete;
  ~Output() {
    if (gzip_) deflateEnd(&stream_);
  }

  /// The caller appends to this string; call maybe_flush() now and then.
  std::string& buffer() { return buffer_; }
  void maybe_flush() {
    if (buffer_.size() >= kChunk) flush(false);
  }
  void commit() {
    flush(true);
    file_.commit();
  }

 private:
  static constexpr std::size_t kChunk = 1 << 20;

  void flush(bool finish) {
    if (!gzip_) {
      file_.write(buffer_.data(), buffer_.size());
      buffer_.clear();
      return;
    }
    stream_.next_in = reinterpret_cast<Bytef*>(buffer_.data());
    stream_.avail_in = static_cast<uInt>(buffer_.size());
    char out[1 << 16];
    int rc = Z_OK;
    do {
      stream_.next_out = reinterpret_cast<Bytef*>(out);
      stream_.avail_out = sizeof(out);
      rc = deflate(&stream_, finish ? Z_FINISH : Z_NO_FLUSH);
      if (rc == Z_STREAM_ERROR) fail(name_, "gzip compression failed");
      file_.write(out, sizeof(out) - stream_.avail_out);
    } while (stream_.avail_out == 0 || (finish && rc != Z_STREAM_END));
    buffer_.clear();
  }

  AtomicFile file_;
  bool gzip_;
  std::string name_;
  z_stream stream_{};
  std::string buffer_;
};

// "PREFIX x y z" (shortest round-trip digits), without the newline.
void append_position(std::string& b, const char* prefix, const Mesh& mesh, Index v, bool as_float = false) {
  b += prefix;
  for (int c = 0; c < 3; ++c) {
    if (c > 0) b += ' ';
    append_double(b, as_float ? static_cast<float>(mesh.V(v, c)) : mesh.V(v, c));
  }
}

// "PREFIX i j k\n" with indices offset by `base` (OBJ counts from 1).
void append_face(std::string& b, const char* prefix, const Mesh& mesh, Index f, Index base = 0) {
  b += prefix;
  for (int c = 0; c < 3; ++c) {
    if (c > 0) b += ' ';
    append_int(b, mesh.F(f, c) + base);
  }
  b += '\n';
}

bool has_colors(const Mesh& mesh, const WriteOptions& options) {
  return options.write_colors && mesh.colors.rows() == mesh.V.rows() && mesh.colors.rows() > 0;
}

void write_obj(Output& out, const Mesh& mesh) {
  std::string& b = out.buffer();
  b += "# written by vertexflow\n";
  for (Index v = 0; v < mesh.num_vertices(); ++v) {
    append_position(b, "v ", mesh, v);
    b += '\n';
    out.maybe_flush();
  }
  for (Index f = 0; f < mesh.num_faces(); ++f) {
    append_face(b, "f ", mesh, f, 1);
    out.maybe_flush();
  }
}

void write_off(Output& out, const Mesh& mesh, const WriteOptions& options) {
  std::string& b = out.buffer();
  const bool colors = has_colors(mesh, options);
  if (options.off_binary) {
    const bool swap = host_is_little_endian();  // binary OFF is big-endian
    b += colors ? "COFF BINARY\n" : "OFF BINARY\n";
    store_scalar<std::int32_t>(b, mesh.num_vertices(), swap);
    store_scalar<std::int32_t>(b, mesh.num_faces(), swap);
    store_scalar<std::int32_t>(b, 0, swap);
    for (Index v = 0; v < mesh.num_vertices(); ++v) {
      for (int c = 0; c < 3; ++c) store_scalar<float>(b, static_cast<float>(mesh.V(v, c)), swap);
      if (colors) {
        for (int c = 0; c < 3; ++c) store_scalar<float>(b, mesh.colors(v, c) / 255.0f, swap);
        store_scalar<float>(b, 1.0f, swap);
      }
      out.maybe_flush();
    }
    for (Index f = 0; f < mesh.num_faces(); ++f) {
      store_scalar<std::int32_t>(b, 3, swap);
      for (int c = 0; c < 3; ++c) store_scalar<std::int32_t>(b, mesh.F(f, c), swap);
      store_scalar<std::int32_t>(b, 0, swap);
      out.maybe_flush();
    }
    return;
  }
  b += colors ? "COFF\n" : "OFF\n";
  b += fmt::format("{} {} 0\n", mesh.num_vertices(), mesh.num_faces());
  for (Index v = 0; v < mesh.num_vertices(); ++v) {
    append_position(b, "", mesh, v);
    if (colors) b += fmt::format(" {} {} {} 255", mesh.colors(v, 0), mesh.colors(v, 1), mesh.colors(v, 2));
    b += '\n';
    out.maybe_flush();
  }
  for (Index f = 0; f < mesh.num_faces(); ++f) {
    append_face(b, "3 ", mesh, f);
    out.maybe_flush();
  }
}

void write_ply(Output& out, const std::string& name, const Mesh& mesh, const WriteOptions& options) {
  std::string& b = out.buffer();
  const bool colors = has_colors(mesh, options);
  std::vector<const VertexProperty*> properties;
  if (options.write_vertex_properties) {
    for (const auto& p : mesh.vertex_properties) {
      if (p.values.size() != mesh.V.rows())
        fail(name, "vertex property '" + p.name + "' has " + std::to_string(p.values.size()) + " values for " +
                       std::to_string(mesh.V.rows()) + " vertices");
      properties.push_back(&p);
    }
  }
  const char* coordinate = options.ply_double_precision ? "double" : "float";
  b += "ply\nformat ";
  b += options.ply_encoding == PlyEncoding::Ascii ? "ascii"
       : options.ply_encoding == PlyEncoding::BinaryBigEndian ? "binary_big_endian"
                                                              : "binary_little_endian";
  b += " 1.0\ncomment written by vertexflow\n";
  b += fmt::format("element vertex {}\nproperty {} x\nproperty {} y\nproperty {} z\n", mesh.num_vertices(),
                   coordinate, coordinate, coordinate);
  if (colors) b += "property uchar red\nproperty uchar green\nproperty uchar blue\n";
  for (const auto* p : properties) b += fmt::format("property double {}\n", p->name);
  b += fmt::format("element face {}\nproperty list uchar int vertex_indices\nend_header\n", mesh.num_faces());

  if (options.ply_encoding == PlyEncoding::Ascii) {
    for (Index v = 0; v < mesh.num_vertices(); ++v) {
      append_position(b, "", mesh, v, !options.ply_double_precision);
      if (colors) b += fmt::format(" {} {} {}", mesh.colors(v, 0), mesh.colors(v, 1), mesh.colors(v, 2));
      for (const auto* p : properties) {
        b += ' ';
        append_double(b, p->values[v]);
      }
      b += '\n';
      out.maybe_flush();
    }
    for (Index f = 0; f < mesh.num_faces(); ++f) {
      append_face(b, "3 ", mesh, f);
      out.maybe_flush();
    }
    return;
  }
  const bool swap = (options.ply_encoding == PlyEncoding::BinaryBigEndian) == host_is_little_endian();
  for (Index v = 0; v < mesh.num_vertices(); ++v) {
    for (int c = 0; c < 3; ++c) {
      if (options.ply_double_precision) store_scalar<double>(b, mesh.V(v, c), swap);
      else store_scalar<float>(b, static_cast<float>(mesh.V(v, c)), swap);
    }
    if (colors) b.append(reinterpret_cast<const char*>(mesh.colors.row(v).data()), 3);
    for (const auto* p : properties) store_scalar<double>(b, p->values[v], swap);
    out.maybe_flush();
  }
  for (Index f = 0; f < mesh.num_faces(); ++f) {
    b += static_cast<char>(3);
    for (int c = 0; c < 3; ++c) store_scalar<std::int32_t>(b, mesh.F(f, c), swap);
    out.maybe_flush();
  }
}

void write_stl(Output& out, const Mesh& mesh, const WriteOptions& options) {
  std::string& b = out.buffer();
  auto normal = [&](Index f) {
    const Eigen::Vector3d n = face_normal(mesh.V, mesh.F, f);
    const double length = n.norm();
    return length > 0 ? Eigen::Vector3d(n / length) : Eigen::Vector3d::Zero();
  };
  if (options.stl_binary) {
    const bool swap = !host_is_little_endian();
    std::string header = "binary STL written by vertexflow";
    header.resize(80, ' ');
    b += header;
    store_scalar<std::uint32_t>(b, static_cast<std::uint32_t>(mesh.num_faces()), swap);
    for (Index f = 0; f < mesh.num_faces(); ++f) {
      const Eigen::Vector3d n = normal(f);
      for (int c = 0; c < 3; ++c) store_scalar<float>(b, static_cast<float>(n[c]), swap);
      for (int k = 0; k < 3; ++k) {
        for (int c = 0; c < 3; ++c) store_scalar<float>(b, static_cast<float>(mesh.V(mesh.F(f, k), c)), swap);
      }
      store_scalar<std::uint16_t>(b, 0, swap);
      out.maybe_flush();
    }
    return;
  }
  b += "solid vertexflow\n";
  for (Index f = 0; f < mesh.num_faces(); ++f) {
    const Eigen::Vector3d n = normal(f);
    b += fmt::format("facet normal {} {} {}\nouter loop\n", n[0], n[1], n[2]);
    for (int k = 0; k < 3; ++k) {
      b += "vertex";
      for (int c = 0; c < 3; ++c) {
        b += ' ';
        append_double(b, mesh.V(mesh.F(f, k), c));
      }
      b += '\n';
    }
    b += "endloop\nendfacet\n";
    out.maybe_flush();
  }
  b += "endsolid vertexflow\n";
}

}  // namespace
}  // namespace io_detail

void write_mesh(const std::filesystem::path& path, const Mesh& mesh, const WriteOptions& options) {
  const MeshFormat format = format_from_path(path);
  const std::string name = path.string();
  if (mesh.F.rows() > 0 && (mesh.F.minCoeff() < 0 || mesh.F.maxCoeff() >= mesh.V.rows()))
    io_detail::fail(name, "cannot write: a face references a vertex that does not exist");
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) io_detail::fail(name, "is a directory");
  io_detail::Output out(path, is_gzip_path(path));
  switch (format) {
    case MeshFormat::Obj: io_detail::write_obj(out, mesh); break;
    case MeshFormat::Ply: io_detail::write_ply(out, name, mesh, options); break;
    case MeshFormat::Off: io_detail::write_off(out, mesh, options); break;
    case MeshFormat::Stl: io_detail::write_stl(out, mesh, options); break;
  }
  out.commit();
}

void write_text_file(const std::filesystem::path& path, std::string_view text) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) io_detail::fail(path.string(), "is a directory");
  io_detail::Output out(path, false);
  out.buffer().append(text);
  out.commit();
}

void check_output_path(const std::filesystem::path& input, const std::filesystem::path& output, bool force,
                       bool mesh_output) {
  std::error_code ec;
  if (std::filesystem::is_directory(output, ec)) io_detail::fail(output.string(), "is a directory, not an output file");
  if (mesh_output) format_from_path(output);
  if (!force && std::filesystem::exists(output, ec) && std::filesystem::equivalent(input, output, ec))
    io_detail::fail(output.string(), "is the input file; refusing to overwrite it (use --force to allow)");
}

}  // namespace vertexflow
