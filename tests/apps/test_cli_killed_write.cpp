// A write killed part-way, by SIGKILL, SIGTERM or SIGINT, leaves no temporary file beside its
// output, and the output is either as it was or complete.
#include "shapes.h"
#include "test_support.h"

#include "vertexflow/io.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <thread>
#include <vector>

#include <fcntl.h>
#include <poll.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

extern char** environ;

namespace vertexflow {
namespace {

std::vector<std::string> entries(const std::filesystem::path& dir) {
  std::vector<std::string> names;
  for (const auto& e : std::filesystem::directory_iterator(dir)) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

// The CLI as a child process whose stderr we read, so we can tell when it starts writing.
class Child {
 public:
  Child(const std::vector<std::string>& arguments, bool no_tmpfile) {
    int fds[2];
    if (::pipe2(fds, O_CLOEXEC) != 0) throw std::runtime_error("pipe");
    err_ = fds[0];
    std::vector<std::string> args = {VERTEXFLOW_CLI};
    args.insert(args.end(), arguments.begin(), arguments.end());
    std::vector<char*> argv;
    for (auto& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    std::vector<std::string> env_strings;
    for (char** e = environ; *e; ++e) {
      if (std::string(*e).rfind("VERTEXFLOW_NO_O_TMPFILE=", 0) != 0) env_strings.emplace_back(*e);
    }
    if (no_tmpfile) env_strings.emplace_back("VERTEXFLOW_NO_O_TMPFILE=1");
    std::vector<char*> envp;
    for (auto& e : env_strings) envp.push_back(e.data());
    envp.push_back(nullptr);
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_adddup2(&actions, fds[1], 2);
    // The child starts with the default disposition of SIGINT and SIGTERM whatever ours is.
    posix_spawnattr_t attr;
    posix_spawnattr_init(&attr);
    sigset_t defaults;
    sigemptyset(&defaults);
    sigaddset(&defaults, SIGINT);
    sigaddset(&defaults, SIGTERM);
    posix_spawnattr_setsigdefault(&attr, &defaults);
    sigset_t none;
    sigemptyset(&none);
    posix_spawnattr_setsigmask(&attr, &none);
    posix_spawnattr_setflags(&attr, POSIX_SPAWN_SETSIGDEF | POSIX_SPAWN_SETSIGMASK);
    const int rc = posix_spawn(&pid_, argv[0], &actions, &attr, argv.data(), envp.data());
    posix_spawn_file_actions_destroy(&actions);
    posix_spawnattr_destroy(&attr);
    ::close(fds[1]);
    if (rc != 0) throw std::runtime_error("posix_spawn failed");
  }
  Child(const Child&) = delete;
  Child& operator=(const Child&) = delete;
  ~Child() {
    if (pid_ > 0) {
      ::kill(pid_, SIGKILL);
      wait();
    }
    ::close(err_);
  }

  // Reads stderr until `text` appears; false if the child closed it first (exited).
  bool wait_for(const std::string& text) {
    while (err_text_.find(text) == std::string::npos) {
      pollfd p{err_, POLLIN, 0};
      if (::poll(&p, 1, 120'000) <= 0) return false;
      char buffer[4096];
      const ssize_t n = ::read(err_, buffer, sizeof(buffer));
      if (n <= 0) return false;
      err_text_.append(buffer, static_cast<std::size_t>(n));
    }
    return true;
  }
  // A zombie until wait(): the pid cannot be reused, so the kill always reaches our child.
  void kill(int signal) const { ::kill(pid_, signal); }
  // The wait status. The read end of stderr stays open, so the child never dies of SIGPIPE.
  int wait() {
    int status = 0;
    while (::waitpid(pid_, &status, 0) < 0 && errno == EINTR) {
    }
    pid_ = -1;
    return status;
  }
  [[nodiscard]] const std::string& err() const { return err_text_; }

 private:
  pid_t pid_ = -1;
  int err_ = -1;
  std::string err_text_;
};

class KilledWrite : public ::testing::Test {
 protected:
  static constexpr int kGrid = 350;

  // An undisturbed run: the complete output, and how long writing it takes.
  static void SetUpTestSuite() {
    input_dir_ = new test::ScratchDir("killed-write-input");
    // About 120k vertices and 250k faces: writing them as gzip-compressed OBJ takes a good
    // fraction of a second, about as long as reading the binary PLY and the zero-round
    // unsharp mask before it, so kill times after the "writing" line fall inside the write.
    input_ = input_dir_->file("grid.ply");
    write_mesh(input_, test::saddle(1.0, kGrid));
    const auto out = input_dir_->file("complete.obj.gz");
    Child child(arguments(out), false);
    if (!child.wait_for("vertexflow: writing ")) return;
    const auto start = std::chrono::steady_clock::now();
    const int status = child.wait();
    write_seconds_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (WIFEXITED(status) && WEXITSTATUS(status) == 0) complete_ = test::read_text(out);
  }
  static void TearDownTestSuite() {
    delete input_dir_;
    input_dir_ = nullptr;
  }

  static std::vector<std::string> arguments(const std::filesystem::path& out) {
    return {"enhance", input_.string(), out.string(), "--method", "unsharp", "--smoothing-iterations", "0"};
  }

  // Kills the CLI at several moments during its write, with `signal`, and checks after each
  // that the directory holds the output only, either as it was or complete: no temporary file.
  static void kill_during_writes(int signal, bool no_tmpfile) {
    ASSERT_FALSE(complete_.empty()) << "the undisturbed run failed";
    ASSERT_EQ(read_mesh_from_memory(complete_, MeshFormat::Obj, "complete.obj.gz").num_vertices(),
              (kGrid + 1) * (kGrid + 1));
    test::ScratchDir dir("killed-write");
    const auto out = dir.file("out.obj.gz");
    const std::string old = "old contents\n";
    // Kill times spread over the write and a little beyond; where each lands (opening, writing,
    // linking, renaming, done) is not asserted: the invariant must hold for all of them.
    const double fractions[] = {0.0, 0.2, 0.4, 0.6, 0.8, 1.0, 1.5};
    int killed = 0;
    for (const double fraction : fractions) {
      SCOPED_TRACE("signal " + std::to_string(signal) + " at " + std::to_string(fraction) + " of the write");
      { std::ofstream(out, std::ios::binary) << old; }
      Child child(arguments(out), no_tmpfile);
      ASSERT_TRUE(child.wait_for("vertexflow: writing ")) << child.err();
      std::this_thread::sleep_for(std::chrono::duration<double>(fraction * write_seconds_));
      child.kill(signal);
      const int status = child.wait();
      // Either it finished first or it died of this very signal (the handler re-raises it).
      EXPECT_TRUE((WIFEXITED(status) && WEXITSTATUS(status) == 0) ||
                  (WIFSIGNALED(status) && WTERMSIG(status) == signal))
          << status << " " << child.err();
      if (WIFSIGNALED(status)) ++killed;
      EXPECT_EQ(entries(dir.path()), std::vector<std::string>{"out.obj.gz"});
      const std::string now = test::read_text(out);
      EXPECT_TRUE(now == old || now == complete_) << now.size() << " bytes, complete " << complete_.size();
    }
    // For the log only: how many kills landed before the command finished.
    std::printf("signal %d%s: %d of %zu runs killed, writing takes %.3f s\n", signal,
                no_tmpfile ? " (named temporary file)" : "", killed, std::size(fractions), write_seconds_);
  }

  static test::ScratchDir* input_dir_;
  static std::filesystem::path input_;
  static std::string complete_;
  static double write_seconds_;
};

test::ScratchDir* KilledWrite::input_dir_ = nullptr;
std::filesystem::path KilledWrite::input_;
std::string KilledWrite::complete_;
double KilledWrite::write_seconds_ = 0;

// With O_TMPFILE the temporary file has no name to leave behind, whatever kills the process;
// only the microseconds between linkat() and rename() would, and a SIGKILL landing exactly
// there is too improbable to make this test flaky.
TEST_F(KilledWrite, SigkillLeavesNoTemporaryFile) {
  kill_during_writes(SIGKILL, false);
}
TEST_F(KilledWrite, SigtermLeavesNoTemporaryFile) {
  kill_during_writes(SIGTERM, false);
}

// Without O_TMPFILE the temporary file is named; the signal handler removes it.
TEST_F(KilledWrite, SigtermRemovesTheNamedTemporaryFile) {
  kill_during_writes(SIGTERM, true);
}
TEST_F(KilledWrite, SigintRemovesTheNamedTemporaryFile) {
  kill_during_writes(SIGINT, true);
}

}  // namespace
}  // namespace vertexflow
