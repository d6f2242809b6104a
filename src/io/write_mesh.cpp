// Writers for OBJ, PLY, OFF and STL, optionally gzip-compressed, with atomic replacement:
// bytes go to a temporary file beside the target (unnamed where the file system allows, so a
// killed process leaves nothing behind), which is renamed over it only when complete.
#include "gltf.h"
#include "io_internal.h"

#include <zlib.h>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <limits>

#include <fcntl.h>
#include <pthread.h>
#include <sys/stat.h>
#include <unistd.h>
#include <algorithm>
#include <array>
#include <atomic>
#include <cerrno>
#include <csignal>
#include <cstdlib>
#include <ctime>
#include <mutex>
#include <random>

namespace vertexflow {
namespace io_detail {
namespace {

// Named temporary files that exist right now, so that SIGINT and SIGTERM can remove them
// before the process dies (SIGKILL cannot be caught: that is why unnamed files come first).
// The handler may run at any moment on any thread, so the registry is fixed storage and
// lock-free atomics only. A slot is Free, Filling (its path being copied in, the file not yet
// created), Armed (the file exists: the handler removes it) or Taken by the handler.
struct TemporarySlot {
  std::atomic<int> state{0};
  char path[4096];  // PATH_MAX: open() refuses longer paths anyway
};
// Concurrent writes; a write beyond that many is simply not protected.
std::array<TemporarySlot, 16> temporary_slots;

// Blocks SIGINT and SIGTERM in the calling thread for its lifetime. Every slot is filled and
// armed (or released) under one, so the handler never runs on the thread that holds a Filling
// slot and may wait for it.
class FillingGuard {
 public:
  FillingGuard() {
    sigset_t blocked;
    sigemptyset(&blocked);
    sigaddset(&blocked, SIGINT);
    sigaddset(&blocked, SIGTERM);
    ::pthread_sigmask(SIG_BLOCK, &blocked, &before_);
  }
  FillingGuard(const FillingGuard&) = delete;
  FillingGuard& operator=(const FillingGuard&) = delete;
  ~FillingGuard() { ::pthread_sigmask(SIG_SETMASK, &before_, nullptr); }

 private:
  sigset_t before_{};
};

class TemporaryRegistry {
 public:
  static constexpr int kNone = -1;

  // Reserves a slot for the file at `path` before it is created; kNone if every slot is busy or
  // the path is too long, and then the file is simply not protected. Call under a FillingGuard
  // and arm() or release() the slot before the guard ends.
  //
  // `path` is absolute_path(name), computed before: from reserve() to arm() or release() the
  // slot is Filling, and the handler on another thread waits for it, so nothing in between may
  // take a lock that handler's thread could hold (malloc's, when the signal interrupted it).
  // Only a copy and a system call come in between.
  static int reserve(const std::string& path) {
    if (path.empty() || path.size() >= sizeof(TemporarySlot::path)) return kNone;
    for (std::size_t i = 0; i < temporary_slots.size(); ++i) {
      int expected = kFree;
      if (temporary_slots[i].state.compare_exchange_strong(expected, kFilling)) {
        std::memcpy(temporary_slots[i].path, path.c_str(), path.size() + 1);
        return static_cast<int>(i);
      }
    }
    return kNone;
  }
  // `name` made absolute, in case the working directory changes before a signal comes (empty
  // if it cannot be); installs the handlers on first use.
  static std::string absolute_path(const std::string& name) {
    install_handlers();
    std::error_code ec;
    std::string path = std::filesystem::absolute(name, ec).string();
    return ec ? std::string() : path;
  }
  // The file now exists. Only from here may the handler unlink the path: before, it could name
  // someone else's file (the O_EXCL or linkat that reports EEXIST).
  static void arm(int slot) {
    if (slot != kNone) temporary_slots[static_cast<std::size_t>(slot)].state.store(kArmed);
  }
  static void release(int slot) {
    if (slot == kNone) return;
    std::atomic<int>& state = temporary_slots[static_cast<std::size_t>(slot)].state;
    int current = state.load();
    // A slot the handler has taken stays taken: the process is about to die.
    while (current != kTaken && !state.compare_exchange_weak(current, kFree)) {
    }
  }

 private:
  enum State { kFree, kFilling, kArmed, kTaken };
  static_assert(std::atomic<int>::is_always_lock_free, "the signal handler needs lock-free atomics");

  static void handle(int signal) {
    for (TemporarySlot& slot : temporary_slots) {
      // A Filling slot belongs to a thread that has these signals blocked (FillingGuard), so
      // this is another thread: wait the few microseconds until its open() or linkat() has
      // returned and the slot is Armed or Free. Skipping it left the file behind (seen in CI:
      // SIGTERM delivered to a worker thread while the main thread was inside linkat()).
      // Bounded (about 0.1 s), so that a slot left Filling for good (a thread stuck in open() on
      // a hung file system, or a fork() child that inherited another thread's slot) cannot make
      // the process ignore the signal; such a file is left behind, as after SIGKILL.
      int state = slot.state.load();
      for (int wait = 0; state == kFilling && wait < 1000; ++wait) {
        const timespec pause{0, 100'000};
        ::nanosleep(&pause, nullptr);  // async-signal-safe
        state = slot.state.load();
      }
      int expected = kArmed;
      if (slot.state.compare_exchange_strong(expected, kTaken)) ::unlink(slot.path);
    }
    // Die of the same signal, so the exit status tells the parent what happened. The signal is
    // blocked while its handler runs; it is delivered, with the default action, on return.
    struct sigaction dfl {};
    dfl.sa_handler = SIG_DFL;
    ::sigaction(signal, &dfl, nullptr);
    ::raise(signal);
  }

  // Once, and only over the default disposition: a program that ignores these signals or
  // handles them itself keeps its choice, and its own clean-up.
  static void install_handlers() {
    static std::once_flag once;
    std::call_once(once, [] {
      for (const int signal : {SIGINT, SIGTERM}) {
        struct sigaction old {};
        if (::sigaction(signal, nullptr, &old) != 0 || (old.sa_flags & SA_SIGINFO) || old.sa_handler != SIG_DFL)
          continue;
        struct sigaction action {};
        action.sa_handler = handle;
        sigemptyset(&action.sa_mask);
        action.sa_flags = SA_RESTART;
        ::sigaction(signal, &action, nullptr);
      }
    });
  }
};

std::string random_hidden_name(const std::filesystem::path& target) {
  static thread_local std::mt19937 random{std::random_device{}()};
  const std::filesystem::path dir = target.has_parent_path() ? target.parent_path() : ".";
  // Hidden, beside the target, so the rename stays on one file system.
  std::string hidden = ".";
  hidden += target.filename().string();
  hidden += ".tmp-";
  hidden += std::to_string(random());
  return (dir / hidden).string();
}

// Whether open(O_TMPFILE) failed because the file system or kernel lacks it (the caller falls
// back to a named file), rather than for a reason a named file would share (EACCES, ENOENT...).
bool tmpfile_unsupported(int error) {
  // EISDIR: kernels before 3.11 see only the O_DIRECTORY bit of O_TMPFILE.
  return error == EOPNOTSUPP || error == EISDIR || error == EINVAL;
}

// A temporary file in the target's directory; commit() renames it into place, the destructor
// discards it if commit() was not reached (an exception, a full disk).
//
// On Linux the file is unnamed (O_TMPFILE): until commit() it has no name, so however the
// process dies (SIGKILL, a crash, power loss) nothing is left behind. commit() gives it a
// short-lived name with linkat() and renames that over the target (linkat cannot replace a
// file). Where O_TMPFILE is unavailable, the file is named from the start, as on other
// systems, and registered for removal on SIGINT and SIGTERM.
class AtomicFile {
 public:
  explicit AtomicFile(std::filesystem::path target) : target_(std::move(target)) {
#ifdef O_TMPFILE
    // VERTEXFLOW_NO_O_TMPFILE: tests take the fallback on file systems that have O_TMPFILE.
    // Without /proc there is no way to give the file a name (AT_EMPTY_PATH needs a capability).
    if (std::getenv("VERTEXFLOW_NO_O_TMPFILE") == nullptr && ::access("/proc/self/fd", X_OK) == 0) {
      const std::filesystem::path dir = target_.has_parent_path() ? target_.parent_path() : ".";
      // Mode 0666, like the named file below: the umask gives the usual permissions.
      fd_ = ::open(dir.c_str(), O_TMPFILE | O_WRONLY | O_CLOEXEC, 0666);
      if (fd_ >= 0) return;
      if (!tmpfile_unsupported(errno)) cannot_create(errno);
    }
#endif
    // O_EXCL with a random suffix makes the name ours; mode 0666 and the umask give the file
    // its usual permissions (mkstemp would give 0600).
    for (int attempt = 0; attempt < 100 && fd_ < 0; ++attempt) {
      int error = 0;
      {
        // SIGINT and SIGTERM wait in this thread while the file is created and armed: a signal
        // between the two left the file behind (seen once in CI, killed as the write began).
        temp_ = random_hidden_name(target_);
        const std::string absolute = TemporaryRegistry::absolute_path(temp_);
        const FillingGuard guard;
        slot_ = TemporaryRegistry::reserve(absolute);
        fd_ = ::open(temp_.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
        error = errno;
        if (fd_ >= 0) {
          TemporaryRegistry::arm(slot_);
          break;
        }
        TemporaryRegistry::release(slot_);
      }
      slot_ = TemporaryRegistry::kNone;
      temp_.clear();
      if (error != EEXIST) cannot_create(error);
    }
    if (fd_ < 0) cannot_create(EEXIST);
  }
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;
  ~AtomicFile() {
    if (fd_ >= 0) ::close(fd_);
    if (!temp_.empty()) ::unlink(temp_.c_str());
    TemporaryRegistry::release(slot_);
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
    if (temp_.empty()) link_unnamed();
    const int fd = fd_;
    fd_ = -1;
    if (::close(fd) != 0) fail(target_.string(), std::string("cannot close: ") + std::strerror(errno));
    if (::rename(temp_.c_str(), target_.c_str()) != 0)
      fail(target_.string(), std::string("cannot rename the temporary file into place: ") + std::strerror(errno));
    temp_.clear();  // it is the target now
    TemporaryRegistry::release(slot_);
    slot_ = TemporaryRegistry::kNone;
  }

 private:
  [[noreturn]] void cannot_create(int error) {
    fail(target_.string(), std::string("cannot create a file in its directory: ") + std::strerror(error));
  }

  // Names the unnamed file. From here to the rename in commit() is the only moment a name
  // exists; it is registered, so SIGINT and SIGTERM remove it (SIGKILL in these few
  // microseconds would leave it).
  void link_unnamed() {
    const std::string proc = "/proc/self/fd/" + std::to_string(fd_);
    for (int attempt = 0; attempt < 100; ++attempt) {
      std::string name = random_hidden_name(target_);
      const std::string absolute = TemporaryRegistry::absolute_path(name);
      const FillingGuard guard;  // as in the constructor: no signal between linkat and arm
      slot_ = TemporaryRegistry::reserve(absolute);
      if (::linkat(AT_FDCWD, proc.c_str(), AT_FDCWD, name.c_str(), AT_SYMLINK_FOLLOW) == 0) {
        TemporaryRegistry::arm(slot_);
        temp_ = std::move(name);
        return;
      }
      const int error = errno;
      TemporaryRegistry::release(slot_);
      slot_ = TemporaryRegistry::kNone;
      if (error != EEXIST)
        fail(target_.string(), std::string("cannot link the temporary file into place: ") + std::strerror(error));
    }
    fail(target_.string(), "cannot link the temporary file into place: no free name");
  }

  std::filesystem::path target_;
  std::string temp_;  // the file's name; empty while it has none (O_TMPFILE) or once committed
  int fd_ = -1;
  int slot_ = TemporaryRegistry::kNone;
};

// Buffers output and passes it to the file, deflating it first for ".gz" targets.
class Output {
 public:
  Output(const std::filesystem::path& path, bool gzip) : file_(path), gzip_(gzip), name_(path.string()) {
    if (gzip_ &&
        deflateInit2(&stream_, Z_DEFAULT_COMPRESSION, Z_DEFLATED, 16 + MAX_WBITS, 8, Z_DEFAULT_STRATEGY) != Z_OK)
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

// PREFIX + each comment + "\n". A control character would end the line (a newline in a PLY
// comment could even write "end_header"), so each becomes '?', as reading does.
void append_comments(std::string& b, std::string_view prefix, const Mesh& mesh) {
  for (const std::string& comment : mesh.comments) {
    b += prefix;
    for (const char c : comment) b += static_cast<unsigned char>(c) < 32 || c == 127 ? '?' : c;
    b += '\n';
  }
}

// The channels each format writes (attributes_not_written names the rest).
struct Written {
  std::vector<const AttributeChannel*> vertex, face;
  const CornerChannel* corner_uv = nullptr;
  const CornerChannel* corner_normal = nullptr;
  const AttributeChannel* vertex_uv = nullptr;      // OBJ: vt per vertex
  const AttributeChannel* vertex_normal = nullptr;  // OBJ: vn per vertex
  const AttributeChannel* color = nullptr;          // OFF
  bool names = false;                               // OBJ's material, group, object names
};

bool is_obj_label(const AttributeChannel& c) {
  return c.width() == 1 && (c.name == "material" || c.name == "group" || c.name == "object" || c.name == "smoothing");
}

Written written_channels(const Mesh& mesh, MeshFormat format, const WriteOptions& options) {
  Written w;
  const MeshAttributes& a = mesh.attributes;
  auto vertex_wanted = [&](const AttributeChannel& c) {
    return c.role == AttributeRole::Color ? options.write_colors : options.write_vertex_properties;
  };
  auto first_corner = [&](AttributeRole role) -> const CornerChannel* {
    if (!options.write_attributes) return nullptr;
    for (const CornerChannel& c : a.corner)
      if (c.channel.role == role && c.corners.rows() == mesh.F.rows()) return &c;
    return nullptr;
  };
  switch (format) {
    case MeshFormat::Ply:
      for (const AttributeChannel& c : a.vertex)
        if (vertex_wanted(c)) w.vertex.push_back(&c);
      if (options.write_attributes)
        for (const AttributeChannel& c : a.face)
          if (c.rows() == mesh.F.rows()) w.face.push_back(&c);
      w.corner_uv = first_corner(AttributeRole::TexCoord);
      if (w.corner_uv && w.corner_uv->channel.width() != 2) w.corner_uv = nullptr;
      break;
    case MeshFormat::Obj:
      w.corner_uv = first_corner(AttributeRole::TexCoord);
      w.corner_normal = first_corner(AttributeRole::Normal);
      for (const AttributeChannel& c : a.vertex) {
        if (!vertex_wanted(c)) continue;
        if (!w.corner_uv && !w.vertex_uv && c.role == AttributeRole::TexCoord && c.width() <= 3) w.vertex_uv = &c;
        if (!w.corner_normal && !w.vertex_normal && c.role == AttributeRole::Normal && c.width() == 3)
          w.vertex_normal = &c;
      }
      if (options.write_attributes)
        for (const AttributeChannel& c : a.face)
          if (c.rows() == mesh.F.rows() && is_obj_label(c)) w.face.push_back(&c);
      w.names = options.write_attributes;
      break;
    case MeshFormat::Off:
      for (const AttributeChannel& c : a.vertex)
        if (!w.color && c.role == AttributeRole::Color && c.width() >= 3 && vertex_wanted(c)) w.color = &c;
      break;
    case MeshFormat::Stl:
      break;
    case MeshFormat::Gltf:  // gltf.cpp decides (the document's channels, or a fresh document's)
      break;
  }
  return w;
}

// A channel's value as the file stores it: ASCII text of its type.
void append_value(std::string& b, double value, ScalarType type) {
  if (is_integer_type(type)) {
    append_int(b, static_cast<std::int64_t>(to_scalar_type(value, type)));
  } else if (type == ScalarType::Float32) {
    char buffer[32];
    const auto result = std::to_chars(buffer, buffer + sizeof(buffer), static_cast<float>(value));
    b.append(buffer, result.ptr);
  } else {
    append_double(b, value);
  }
}

void store_value(std::string& b, double value, ScalarType type, bool swap) {
  const double v = to_scalar_type(value, type);
  switch (type) {
    case ScalarType::Int8:
      return store_scalar<std::int8_t>(b, static_cast<std::int8_t>(v), swap);
    case ScalarType::UInt8:
      return store_scalar<std::uint8_t>(b, static_cast<std::uint8_t>(v), swap);
    case ScalarType::Int16:
      return store_scalar<std::int16_t>(b, static_cast<std::int16_t>(v), swap);
    case ScalarType::UInt16:
      return store_scalar<std::uint16_t>(b, static_cast<std::uint16_t>(v), swap);
    case ScalarType::Int32:
      return store_scalar<std::int32_t>(b, static_cast<std::int32_t>(v), swap);
    case ScalarType::UInt32:
      return store_scalar<std::uint32_t>(b, static_cast<std::uint32_t>(v), swap);
    case ScalarType::Float32:
      return store_scalar<float>(b, static_cast<float>(v), swap);
    case ScalarType::Float64:
      return store_scalar<double>(b, v, swap);
  }
}

const char* ply_type_name(ScalarType type) {
  static constexpr const char* names[] = {"char", "uchar", "short", "ushort", "int", "uint", "float", "double"};
  return names[static_cast<int>(type)];
}

// OBJ: the channel's rows as `PREFIX a b c` lines.
void append_rows(Output& out, const char* prefix, const AttributeChannel& channel) {
  std::string& b = out.buffer();
  for (Eigen::Index r = 0; r < channel.rows(); ++r) {
    b += prefix;
    for (int k = 0; k < channel.width(); ++k) {
      b += ' ';
      append_double(b, channel.values(r, k));
    }
    b += '\n';
    out.maybe_flush();
  }
}

void write_obj(Output& out, const Mesh& mesh, const WriteOptions& options) {
  const Written w = written_channels(mesh, MeshFormat::Obj, options);
  const MeshAttributes& a = mesh.attributes;
  std::string& b = out.buffer();
  b += "# written by vertexflow\n";
  append_comments(b, "# ", mesh);
  if (w.names)
    for (const std::string& library : a.material_libraries) b += "mtllib " + library + "\n";
  for (Index v = 0; v < mesh.num_vertices(); ++v) {
    append_position(b, "v ", mesh, v);
    b += '\n';
    out.maybe_flush();
  }
  const AttributeChannel* uv = w.corner_uv ? &w.corner_uv->channel : w.vertex_uv;
  const AttributeChannel* normal = w.corner_normal ? &w.corner_normal->channel : w.vertex_normal;
  if (uv) append_rows(out, "vt", *uv);
  if (normal) append_rows(out, "vn", *normal);
  // Labels are written where they change, in OBJ's order: object, group, material, smoothing.
  struct Label {
    const AttributeChannel* channel = nullptr;
    const std::vector<std::string>* names = nullptr;
    const char* keyword = "";
    double last = std::numeric_limits<double>::quiet_NaN();
  };
  std::vector<Label> labels;
  for (const char* name : {"object", "group", "material", "smoothing"}) {
    for (const AttributeChannel* c : w.face) {
      if (c->name != name) continue;
      Label label;
      label.channel = c;
      label.keyword = c->name == "object" ? "o" : c->name == "group" ? "g" : c->name == "material" ? "usemtl" : "s";
      label.names = c->name == "object"     ? &a.objects
                    : c->name == "group"    ? &a.groups
                    : c->name == "material" ? &a.materials
                                            : nullptr;
      labels.push_back(label);
    }
  }
  auto corner_row = [&](const CornerChannel* corner, const AttributeChannel* per_vertex, Index f,
                        int k) -> std::int64_t {
    if (corner) return corner->corners(f, k);
    return per_vertex ? mesh.F(f, k) : -1;
  };
  for (Index f = 0; f < mesh.num_faces(); ++f) {
    for (Label& label : labels) {
      const double value = label.channel->values(f, 0);
      if (value == label.last) continue;
      label.last = value;
      const auto index = static_cast<std::int64_t>(value);
      if (label.names == nullptr) {
        b += index == 0 ? "s off\n" : fmt::format("s {}\n", index);
      } else if (index >= 0 && index < static_cast<std::int64_t>(label.names->size())) {
        b += fmt::format("{} {}\n", label.keyword, (*label.names)[static_cast<std::size_t>(index)]);
      } else if (label.keyword[0] != 'u') {
        b += fmt::format("{}\n", label.keyword);  // back to no group or object
      }
    }
    b += "f ";
    for (int k = 0; k < 3; ++k) {
      if (k > 0) b += ' ';
      append_int(b, mesh.F(f, k) + 1);
      const std::int64_t t = corner_row(w.corner_uv, w.vertex_uv, f, k);
      const std::int64_t n = corner_row(w.corner_normal, w.vertex_normal, f, k);
      if (t >= 0 || n >= 0) {
        b += '/';
        if (t >= 0) append_int(b, t + 1);
      }
      if (n >= 0) {
        b += '/';
        append_int(b, n + 1);
      }
    }
    b += '\n';
    out.maybe_flush();
  }
}

void write_off(Output& out, const Mesh& mesh, const WriteOptions& options) {
  std::string& b = out.buffer();
  const Colors colors = written_channels(mesh, MeshFormat::Off, options).color ? mesh.vertex_colors() : Colors();
  const bool has_colors = colors.rows() > 0;
  if (options.off_binary) {
    const bool swap = host_is_little_endian();  // binary OFF is big-endian
    b += has_colors ? "COFF BINARY\n" : "OFF BINARY\n";
    store_scalar<std::int32_t>(b, mesh.num_vertices(), swap);
    store_scalar<std::int32_t>(b, mesh.num_faces(), swap);
    store_scalar<std::int32_t>(b, 0, swap);
    for (Index v = 0; v < mesh.num_vertices(); ++v) {
      for (int c = 0; c < 3; ++c) store_scalar<float>(b, static_cast<float>(mesh.V(v, c)), swap);
      if (has_colors) {
        for (int c = 0; c < 3; ++c) store_scalar<float>(b, colors(v, c) / 255.0f, swap);
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
  b += has_colors ? "COFF\n" : "OFF\n";
  // After the keyword line, which many readers (PMP's) expect first.
  append_comments(b, "# ", mesh);
  b += fmt::format("{} {} 0\n", mesh.num_vertices(), mesh.num_faces());
  for (Index v = 0; v < mesh.num_vertices(); ++v) {
    append_position(b, "", mesh, v);
    if (has_colors) b += fmt::format(" {} {} {} 255", colors(v, 0), colors(v, 1), colors(v, 2));
    b += '\n';
    out.maybe_flush();
  }
  for (Index f = 0; f < mesh.num_faces(); ++f) {
    append_face(b, "3 ", mesh, f);
    out.maybe_flush();
  }
}

void write_ply(Output& out, const Mesh& mesh, const WriteOptions& options) {
  std::string& b = out.buffer();
  const Written w = written_channels(mesh, MeshFormat::Ply, options);
  const AttributeChannel* texcoord = w.corner_uv ? &w.corner_uv->channel : nullptr;
  const char* coordinate = options.ply_double_precision ? "double" : "float";
  b += "ply\nformat ";
  b += options.ply_encoding == PlyEncoding::Ascii             ? "ascii"
       : options.ply_encoding == PlyEncoding::BinaryBigEndian ? "binary_big_endian"
                                                              : "binary_little_endian";
  b += " 1.0\ncomment written by vertexflow\n";
  append_comments(b, "comment ", mesh);
  b += fmt::format("element vertex {}\nproperty {} x\nproperty {} y\nproperty {} z\n", mesh.num_vertices(), coordinate,
                   coordinate, coordinate);
  for (const AttributeChannel* c : w.vertex)
    for (const std::string& component : c->components)
      b += fmt::format("property {} {}\n", ply_type_name(c->type), component);
  b += fmt::format("element face {}\nproperty list uchar int vertex_indices\n", mesh.num_faces());
  for (const AttributeChannel* c : w.face)
    for (const std::string& component : c->components)
      b += fmt::format("property {} {}\n", ply_type_name(c->type), component);
  if (texcoord)
    b += fmt::format("property list uchar {} {}\n", ply_type_name(texcoord->type),
                     texcoord->name == "uv" ? "texcoord" : texcoord->name);
  b += "end_header\n";
  // A corner without a texture coordinate (OBJ `f 1 2/3 4`) is written as (0, 0).
  auto texcoord_value = [&](Index f, int k, int c) {
    const std::int32_t row = w.corner_uv->corners(f, k);
    return row >= 0 ? texcoord->values(row, c) : 0.0;
  };

  if (options.ply_encoding == PlyEncoding::Ascii) {
    for (Index v = 0; v < mesh.num_vertices(); ++v) {
      append_position(b, "", mesh, v, !options.ply_double_precision);
      for (const AttributeChannel* c : w.vertex)
        for (int k = 0; k < c->width(); ++k) {
          b += ' ';
          append_value(b, c->values(v, k), c->type);
        }
      b += '\n';
      out.maybe_flush();
    }
    for (Index f = 0; f < mesh.num_faces(); ++f) {
      b += "3 ";
      for (int k = 0; k < 3; ++k) {
        if (k > 0) b += ' ';
        append_int(b, mesh.F(f, k));
      }
      for (const AttributeChannel* c : w.face)
        for (int k = 0; k < c->width(); ++k) {
          b += ' ';
          append_value(b, c->values(f, k), c->type);
        }
      if (texcoord) {
        b += " 6";
        for (int k = 0; k < 3; ++k)
          for (int c = 0; c < 2; ++c) {
            b += ' ';
            append_value(b, texcoord_value(f, k, c), texcoord->type);
          }
      }
      b += '\n';
      out.maybe_flush();
    }
    return;
  }
  const bool swap = (options.ply_encoding == PlyEncoding::BinaryBigEndian) == host_is_little_endian();
  for (Index v = 0; v < mesh.num_vertices(); ++v) {
    for (int c = 0; c < 3; ++c) {
      if (options.ply_double_precision)
        store_scalar<double>(b, mesh.V(v, c), swap);
      else
        store_scalar<float>(b, static_cast<float>(mesh.V(v, c)), swap);
    }
    for (const AttributeChannel* c : w.vertex)
      for (int k = 0; k < c->width(); ++k) store_value(b, c->values(v, k), c->type, swap);
    out.maybe_flush();
  }
  for (Index f = 0; f < mesh.num_faces(); ++f) {
    b += static_cast<char>(3);
    for (int c = 0; c < 3; ++c) store_scalar<std::int32_t>(b, mesh.F(f, c), swap);
    for (const AttributeChannel* c : w.face)
      for (int k = 0; k < c->width(); ++k) store_value(b, c->values(f, k), c->type, swap);
    if (texcoord) {
      b += static_cast<char>(6);
      for (int k = 0; k < 3; ++k)
        for (int c = 0; c < 2; ++c) store_value(b, texcoord_value(f, k, c), texcoord->type, swap);
    }
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
  try {
    mesh.attributes.validate(mesh.V.rows(), mesh.F.rows());
  } catch (const std::invalid_argument& e) {
    io_detail::fail(name, e.what());
  }
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) io_detail::fail(name, "is a directory");
  io_detail::Output out(path, is_gzip_path(path));
  switch (format) {
    case MeshFormat::Obj:
      io_detail::write_obj(out, mesh, options);
      break;
    case MeshFormat::Ply:
      io_detail::write_ply(out, mesh, options);
      break;
    case MeshFormat::Off:
      io_detail::write_off(out, mesh, options);
      break;
    case MeshFormat::Stl:
      io_detail::write_stl(out, mesh, options);
      break;
    case MeshFormat::Gltf:
      out.buffer() += io_detail::write_gltf(path, mesh, lowercase_extension(path) == ".glb");
      break;
  }
  out.commit();
}

std::string attributes_not_written_warning(const Mesh& mesh, MeshFormat format, const WriteOptions& options) {
  const std::vector<std::string> lost = attributes_not_written(mesh, format, options);
  if (lost.empty()) return {};
  return fmt::format("{} cannot hold, so it does not get: {}", format_name(format), fmt::join(lost, ", "));
}

std::vector<std::string> attributes_not_written(const Mesh& mesh, MeshFormat format, const WriteOptions& options) {
  if (format == MeshFormat::Gltf) return io_detail::gltf_attributes_not_written(mesh);
  const io_detail::Written w = io_detail::written_channels(mesh, format, options);
  const MeshAttributes& a = mesh.attributes;
  std::vector<std::string> out;
  auto contains = [](const auto& list, const auto* item) {
    return std::find(list.begin(), list.end(), item) != list.end();
  };
  for (const AttributeChannel& c : a.vertex)
    if (!contains(w.vertex, &c) && &c != w.vertex_uv && &c != w.vertex_normal && &c != w.color)
      out.push_back("vertex " + c.name);
  for (const CornerChannel& c : a.corner)
    if (&c != w.corner_uv && &c != w.corner_normal) out.push_back("corner " + c.channel.name);
  for (const AttributeChannel& c : a.face)
    if (!contains(w.face, &c)) out.push_back("face " + c.name);
  if (!w.names) {
    if (!a.materials.empty()) out.push_back("material names");
    if (!a.groups.empty()) out.push_back("group names");
    if (!a.objects.empty()) out.push_back("object names");
    if (!a.material_libraries.empty()) out.push_back("mtllib");
  }
  return out;
}

void write_text_file(const std::filesystem::path& path, std::string_view text) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) io_detail::fail(path.string(), "is a directory");
  io_detail::Output out(path, false);
  out.buffer().append(text);
  out.commit();
}

void check_output_writable(const std::filesystem::path& output) {
  std::error_code ec;
  if (std::filesystem::is_directory(output, ec)) io_detail::fail(output.string(), "is a directory, not an output file");
  // The very file a write would start with, discarded at once: whatever would stop the write
  // (a missing directory, permissions, a read-only file system, a parent that is not a
  // directory) stops this, and nothing is left behind.
  io_detail::AtomicFile probe(output);
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
