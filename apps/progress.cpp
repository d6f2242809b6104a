#include "progress.h"

#include "vertexflow/timing.h"

#include <fmt/format.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <cstdlib>
#include <mutex>
#include <string>
#include <thread>

#include <sys/ioctl.h>
#include <unistd.h>

namespace vertexflow::cli {
namespace {

// Erases the terminal's current line: back to its start, then clear to its end.
constexpr std::string_view kClearLine = "\r\033[K";

// Writes all of `text` to `fd`, retrying after signals; gives up on other errors (a progress
// line is not worth failing a command for).
void write_all(int fd, std::string_view text) {
  while (!text.empty()) {
    const ssize_t n = ::write(fd, text.data(), text.size());
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return;
    text.remove_prefix(static_cast<std::size_t>(n));
  }
}

std::string clock_text(double seconds) {
  const long s = std::lround(std::max(0.0, seconds));
  return s >= 3600 ? fmt::format("{}:{:02}:{:02}", s / 3600, s / 60 % 60, s % 60)
                   : fmt::format("{}:{:02}", s / 60, s % 60);
}

double delay_from_environment() {
  if (const char* text = std::getenv("VERTEXFLOW_PROGRESS_DELAY")) {
    char* end = nullptr;
    const double seconds = std::strtod(text, &end);
    if (end != text && *end == '\0' && std::isfinite(seconds) && seconds >= 0) return seconds;
  }
  return ProgressLine::kProgressDelay;
}

// The terminal's width in columns (80 when it does not say).
std::size_t terminal_columns(int fd) {
  winsize size{};
  if (::ioctl(fd, TIOCGWINSZ, &size) == 0 && size.ws_col > 0) return size.ws_col;
  return 80;
}

}  // namespace

struct ProgressLine::Impl {
  // One stdio stream (stderr, or stdout on a terminal) swapped for one that clears the line
  // before its bytes go to the stream's descriptor.
  struct Stream {
    Impl* impl = nullptr;
    int fd = -1;
    FILE* original = nullptr;
    FILE* replacement = nullptr;
  };

  std::mutex mutex;  // everything below, and every write to the terminal
  std::condition_variable wake;
  const Clock::time_point start = Clock::now();
  const double delay = delay_from_environment();
  std::string phase;  // empty: nothing reported yet
  double begin = 0, end = 0, phase_started = 0, shown_fraction = 0;
  bool known = true;
  bool visible = false;       // the line is on the terminal
  bool at_line_start = true;  // others' last byte ended a line (or nothing was written)
  bool stopped = false;
  std::string shown;
  Stream err, out;
  std::thread ticker;

  Impl() = default;
  Impl(const Impl&) = delete;
  Impl& operator=(const Impl&) = delete;
  ~Impl() { stop(); }  // also when ProgressLine's constructor throws after this was made

  double elapsed() const { return seconds_since(start); }

  void clear_locked() {
    if (!visible) return;
    write_all(err.fd, kClearLine);
    visible = false;
  }

  // The line's text now: the phase, then the percent and the ETA (or the elapsed time).
  std::string text_locked() {
    const double now = elapsed();
    if (!known) return fmt::format("vertexflow: {}  {} elapsed", phase, clock_text(now));
    double done = begin;
    // Within the phase: advance at the rate of the phases before it, up to 95% of it.
    if (begin >= 0.01 && end > begin && phase_started > 0) {
      const double expected = (end - begin) * phase_started / begin;
      done = begin + (end - begin) * std::min(0.95, (now - phase_started) / expected);
    }
    done = shown_fraction = std::max(shown_fraction, std::min(done, 1.0));
    const int percent = std::min(99, static_cast<int>(100 * done));
    if (done < 0.01) return fmt::format("vertexflow: {}  {:2}%  {} elapsed", phase, percent, clock_text(now));
    return fmt::format("vertexflow: {}  {:2}%  ETA {}", phase, percent, clock_text(now * (1 - done) / done));
  }

  void draw_locked() {
    if (stopped || phase.empty() || !at_line_start || elapsed() < delay) return;
    std::string text = text_locked();
    // Never wider than the terminal: a wrapped line cannot be rewritten with "\r".
    const std::size_t columns = terminal_columns(err.fd);
    if (text.size() >= columns) text.resize(columns - 1);
    if (visible && text == shown) return;
    write_all(err.fd, std::string(kClearLine) + text);
    visible = true;
    shown = std::move(text);
  }

  // The replacement streams' write function (fopencookie).
  static ssize_t write_through(void* cookie, const char* data, std::size_t size) {
    Stream& stream = *static_cast<Stream*>(cookie);
    Impl& impl = *stream.impl;
    const std::lock_guard lock(impl.mutex);
    impl.clear_locked();
    write_all(stream.fd, std::string_view(data, size));
    if (size > 0) impl.at_line_start = data[size - 1] == '\n';
    return static_cast<ssize_t>(size);
  }

  // Swaps `slot` (stdio's stderr or stdout) for a stream through write_through.
  void swap_in(Stream& stream, FILE*& slot, int mode) {
    std::fflush(slot);
    cookie_io_functions_t functions{};
    functions.write = &Impl::write_through;
    stream.impl = this;
    stream.fd = ::fileno(slot);
    stream.original = slot;
    stream.replacement = ::fopencookie(&stream, "w", functions);
    if (!stream.replacement) return;  // then that stream is left as it is
    std::setvbuf(stream.replacement, nullptr, mode, BUFSIZ);
    slot = stream.replacement;
  }

  void swap_out(Stream& stream, FILE*& slot) {
    if (!stream.replacement) return;
    std::fflush(stream.replacement);  // through write_through: takes the mutex
    slot = stream.original;
    std::fclose(stream.replacement);
    stream.replacement = nullptr;
  }

  void run_ticker() {
    std::unique_lock lock(mutex);
    while (!stopped) {
      wake.wait_for(lock, std::chrono::milliseconds(100));  // at most 10 redraws a second
      draw_locked();
    }
  }

  // Stops the ticker, restores the streams and leaves the terminal's line empty. Idempotent.
  void stop() {
    {
      const std::lock_guard lock(mutex);
      if (stopped) return;
      stopped = true;
    }
    wake.notify_all();
    if (ticker.joinable()) ticker.join();
    swap_out(out, stdout);
    swap_out(err, stderr);
    const std::lock_guard lock(mutex);
    clear_locked();
  }
};

ProgressLine::ProgressLine(const GlobalOptions& global) {
  if (global.quiet || ::isatty(STDERR_FILENO) != 1) return;
  impl_ = std::make_unique<Impl>();
  impl_->ticker = std::thread([impl = impl_.get()] { impl->run_ticker(); });
  // stderr unbuffered, as it was; stdout on a terminal line-buffered, as it was.
  impl_->swap_in(impl_->err, stderr, _IONBF);
  if (::isatty(STDOUT_FILENO) == 1) impl_->swap_in(impl_->out, stdout, _IOLBF);
  scope_ = std::make_unique<ProgressScope>([this](const Progress& p) { report(p.phase, p.begin, p.end); });
}

ProgressLine::~ProgressLine() {
  scope_.reset();
  impl_.reset();  // stops the ticker, restores the streams, clears the line
}

void ProgressLine::report(std::string_view phase, double begin, double end) {
  if (!impl_) return;
  const std::lock_guard lock(impl_->mutex);
  impl_->phase = phase;
  impl_->begin = begin;
  impl_->end = std::max(begin, end);
  impl_->phase_started = impl_->elapsed();
  impl_->known = true;
}

void ProgressLine::report_unknown(std::string_view phase) {
  if (!impl_) return;
  const std::lock_guard lock(impl_->mutex);
  impl_->phase = phase;
  impl_->known = false;
}

void ProgressLine::finish() {
  if (impl_) impl_->stop();
}

std::vector<double> progress_bounds(std::initializer_list<double> weights) {
  double total = 0;
  for (const double w : weights) total += w;
  std::vector<double> bounds{0};
  double sum = 0;
  for (const double w : weights) {
    sum += w;
    bounds.push_back(total > 0 ? sum / total : 1);
  }
  return bounds;
}

}  // namespace vertexflow::cli
