// Progress (issue 29): the engine reports its phases (progress.h), and the CLI shows them on a
// terminal as one line rewritten in place ("vertexflow: solve  45%  ETA 0:03", apps/progress.h),
// which is cleared before any other output and at the end; with stderr redirected, or with
// --quiet, nothing of it appears.
//
// The CLI runs on a pseudo-terminal (forkpty) in raw mode, so the bytes read from it are the
// bytes the CLI wrote; VERTEXFLOW_PROGRESS_DELAY=0 shows the line from the first phase on
// instead of after 2 s, so runs of about a second are enough.
#include "test_support.h"

#include "vertexflow/enhance.h"
#include "vertexflow/io.h"
#include "vertexflow/progress.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <regex>
#include <string>
#include <vector>

#include <fcntl.h>
#include <poll.h>
#include <pty.h>
#include <signal.h>
#include <sys/wait.h>
#include <termios.h>
#include <unistd.h>

namespace vertexflow {
namespace {

constexpr std::string_view kClear = "\r\033[K";
constexpr int kColumns = 100;

struct TerminalRun {
  int exit_code = -1;    // -1: killed by a signal (or by the watchdog)
  std::string terminal;  // everything the CLI wrote to the terminal
};

// Runs the CLI with `arguments` on a pseudo-terminal of kColumns columns (stdin, stdout and
// stderr; stderr to `stderr_file` instead when given) with `environment` ("NAME=value") added.
// A watchdog kills a run that takes longer than 120 s.
TerminalRun run_on_terminal(const std::vector<std::string>& arguments, const std::vector<std::string>& environment,
                            const std::filesystem::path& stderr_file = {}) {
  termios raw{};
  cfmakeraw(&raw);
  winsize size{};
  size.ws_row = 24;
  size.ws_col = kColumns;
  // Everything the child needs is built before the fork.
  std::vector<std::string> words{VERTEXFLOW_CLI};
  words.insert(words.end(), arguments.begin(), arguments.end());
  std::vector<char*> argv;
  for (std::string& w : words) argv.push_back(w.data());
  argv.push_back(nullptr);
  std::vector<std::string> env_entries = environment;
  const std::string error_path = stderr_file.string();

  int master = -1;
  const pid_t pid = forkpty(&master, nullptr, &raw, &size);
  if (pid < 0) {
    ADD_FAILURE() << "forkpty: " << std::strerror(errno);
    return {};
  }
  if (pid == 0) {
    for (std::string& e : env_entries) ::putenv(e.data());
    if (!error_path.empty()) {
      const int fd = ::open(error_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      if (fd < 0 || ::dup2(fd, STDERR_FILENO) < 0) ::_exit(126);
      ::close(fd);
    }
    ::execv(argv[0], argv.data());
    ::_exit(127);
  }
  TerminalRun run;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(120);
  char buffer[4096];
  for (;;) {
    const auto left =
        std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
    pollfd p{master, POLLIN, 0};
    const int ready = ::poll(&p, 1, static_cast<int>(std::max<long long>(0, left.count())));
    if (ready == 0) {
      ADD_FAILURE() << "the CLI ran over 120 s; killed";
      ::kill(pid, SIGKILL);
      break;
    }
    if (ready < 0 && errno == EINTR) continue;
    const ssize_t n = ::read(master, buffer, sizeof buffer);
    if (n > 0) {
      run.terminal.append(buffer, static_cast<std::size_t>(n));
      continue;
    }
    if (n < 0 && errno == EINTR) continue;
    break;  // EIO: the child's side is closed
  }
  int status = 0;
  ::waitpid(pid, &status, 0);
  ::close(master);
  run.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return run;
}

// What a terminal run wrote, taken apart at each "\r\033[K": the progress line's drawings (a
// piece without a newline) and the other output (pieces of whole lines).
struct TerminalPieces {
  std::vector<std::string> drawings;
  std::string other;       // the other output, in order
  std::size_t clears = 0;  // "\r\033[K" sequences
  bool ends_cleanly = false;
};

TerminalPieces take_apart(const std::string& terminal) {
  TerminalPieces pieces;
  std::size_t at = 0;
  std::string last;
  for (;;) {
    const std::size_t next = terminal.find(kClear, at);
    const std::string piece = terminal.substr(at, next == std::string::npos ? std::string::npos : next - at);
    if (!piece.empty() && piece.find('\n') == std::string::npos)
      pieces.drawings.push_back(piece);
    else
      pieces.other += piece;
    last = piece;
    if (next == std::string::npos) break;
    ++pieces.clears;
    at = next + kClear.size();
  }
  // The last thing written is a clear, or whole lines: no drawing is left on the terminal.
  pieces.ends_cleanly = last.empty() || last.back() == '\n';
  return pieces;
}

std::string read_bytes(const std::filesystem::path& path) {
  return test::read_text(path);
}

// Digits out: phase lines carry timings, which differ between runs.
std::string without_digits(std::string s) {
  std::replace_if(
      s.begin(), s.end(), [](char c) { return c >= '0' && c <= '9'; }, '#');
  return s;
}

const std::regex kDrawing(R"(vertexflow: .+  ([ \d]\d%  (ETA \d+:\d\d|\d+:\d\d elapsed)|\d+:\d\d elapsed))");

// The enhance run of these tests: horse-48k (48k vertices; 0.4-1.5 s, 1-5 s with the report's
// metrics), into `directory`.
std::vector<std::string> enhance_arguments(const std::filesystem::path& directory, bool report = true) {
  std::vector<std::string> arguments{"enhance", test::data_path("horse-48k.ply").string(),
                                     (directory / "out.ply").string()};
  if (report) arguments.insert(arguments.end(), {"--report", (directory / "report.json").string()});
  return arguments;
}

TEST(CliProgress, OnATerminalTheLineAppearsUpdatesAndEndsCleared) {
  const test::ScratchDir scratch("progress-terminal");
  std::filesystem::create_directory(scratch.file("tty"));
  std::filesystem::create_directory(scratch.file("plain"));
  const TerminalRun run = run_on_terminal(enhance_arguments(scratch.file("tty")), {"VERTEXFLOW_PROGRESS_DELAY=0"});
  ASSERT_EQ(run.exit_code, 0) << run.terminal;
  const TerminalPieces pieces = take_apart(run.terminal);
  // Drawn, with a percent, and redrawn as the phases pass (measured with the machine's 2 cores
  // shared, 2.5-5 s runs: 10-15 drawings, all distinct, of 5-6 phases; 12-18 clears).
  ASSERT_GE(pieces.drawings.size(), 3u) << run.terminal;
  EXPECT_GE(pieces.clears, 4u) << run.terminal;
  std::vector<std::string> distinct = pieces.drawings;
  std::sort(distinct.begin(), distinct.end());
  distinct.erase(std::unique(distinct.begin(), distinct.end()), distinct.end());
  EXPECT_GE(distinct.size(), 3u) << run.terminal;
  bool percent = false;
  for (const std::string& d : pieces.drawings) {
    EXPECT_TRUE(std::regex_match(d, kDrawing)) << "'" << d << "'";
    EXPECT_LT(d.size(), static_cast<std::size_t>(kColumns)) << d;  // never wraps
    percent = percent || std::regex_search(d, std::regex(R"(\d%  ETA \d+:\d\d)"));
  }
  EXPECT_TRUE(percent) << run.terminal;
  // The phases of the engine and of the command show: the flow's solve and the report's metrics.
  const auto shown = [&](const std::string& what) {
    return std::any_of(pieces.drawings.begin(), pieces.drawings.end(),
                       [&](const std::string& d) { return d.find(what) != std::string::npos; });
  };
  EXPECT_TRUE(shown("vertexflow: solve")) << run.terminal;
  EXPECT_TRUE(shown("vertexflow: metrics")) << run.terminal;
  // Ends cleanly: the last drawing was cleared, nothing dangles.
  EXPECT_TRUE(pieces.ends_cleanly) << run.terminal;
  EXPECT_TRUE(run.terminal.ends_with(kClear) || run.terminal.ends_with("\n")) << run.terminal;

  // The same run without a terminal: the same mesh, and the terminal got what stderr gets then
  // (timings and the directory aside).
  std::string arguments;
  for (const std::string& a : enhance_arguments(scratch.file("plain"))) arguments += test::shell_quote(a) + " ";
  const test::CommandResult plain = test::run_cli(arguments);
  ASSERT_EQ(plain.exit_code, 0) << plain.err;
  EXPECT_EQ(read_bytes(scratch.file("tty") / "out.ply"), read_bytes(scratch.file("plain") / "out.ply"));
  std::string other = take_apart(run.terminal).other;
  for (std::size_t at; (at = other.find("/tty/")) != std::string::npos;) other.replace(at, 5, "/plain/");
  EXPECT_EQ(without_digits(other), without_digits(plain.err));
  // No progress without a terminal: no carriage return, no escape sequence.
  EXPECT_EQ(plain.err.find('\r'), std::string::npos) << plain.err;
  EXPECT_EQ(plain.err.find('\033'), std::string::npos) << plain.err;
}

TEST(CliProgress, NothingWhenStderrIsRedirected) {
  const test::ScratchDir scratch("progress-redirected");
  const std::filesystem::path err = scratch.file("stderr.txt");
  const TerminalRun run =
      run_on_terminal(enhance_arguments(scratch.path(), false), {"VERTEXFLOW_PROGRESS_DELAY=0"}, err);
  ASSERT_EQ(run.exit_code, 0) << read_bytes(err);
  // stdout is still the terminal, and gets nothing; stderr has its lines and nothing else.
  EXPECT_EQ(run.terminal, "");
  const std::string text = read_bytes(err);
  EXPECT_NE(text.find("vertexflow: reading"), std::string::npos) << text;
  EXPECT_EQ(text.find('\r'), std::string::npos) << text;
  EXPECT_EQ(text.find('\033'), std::string::npos) << text;
  EXPECT_EQ(text.find('%'), std::string::npos) << text;
}

TEST(CliProgress, NothingWithQuietOnATerminal) {
  const test::ScratchDir scratch("progress-quiet");
  std::vector<std::string> arguments = enhance_arguments(scratch.path(), false);
  arguments.insert(arguments.begin(), "--quiet");
  const TerminalRun run = run_on_terminal(arguments, {"VERTEXFLOW_PROGRESS_DELAY=0"});
  ASSERT_EQ(run.exit_code, 0) << run.terminal;
  EXPECT_EQ(run.terminal, "");
  EXPECT_TRUE(std::filesystem::exists(scratch.file("out.ply")));
}

TEST(CliProgress, NothingBeforeTheDelay) {
  // The default delay, 2 s, is longer than this run (bunny_uniform: about 0.1 s).
  const test::ScratchDir scratch("progress-delay");
  const TerminalRun run =
      run_on_terminal({"enhance", test::data_path("bunny_uniform.off").string(), scratch.file("out.ply").string()}, {});
  ASSERT_EQ(run.exit_code, 0) << run.terminal;
  EXPECT_EQ(run.terminal.find(kClear), std::string::npos) << run.terminal;
  EXPECT_NE(run.terminal.find("vertexflow: writing"), std::string::npos) << run.terminal;
}

TEST(CliProgress, AnErrorLineStartsALineOfItsOwn) {
  // The reference is read (the line shows), then refused by the engine: the error line comes
  // after the line was cleared, on a line of its own, and nothing follows it.
  const test::ScratchDir scratch("progress-error");
  const TerminalRun run =
      run_on_terminal({"enhance", test::data_path("horse-48k.ply").string(), scratch.file("out.ply").string(),
                       "--reference", test::data_path("bunny.off").string()},
                      {"VERTEXFLOW_PROGRESS_DELAY=0"});
  EXPECT_EQ(run.exit_code, 1) << run.terminal;
  const std::size_t error = run.terminal.find("vertexflow: error: ");
  ASSERT_NE(error, std::string::npos) << run.terminal;
  const std::string before = run.terminal.substr(0, error);
  EXPECT_TRUE(before.empty() || before.ends_with("\n") || before.ends_with(kClear)) << run.terminal;
  EXPECT_TRUE(take_apart(run.terminal.substr(0, error)).ends_cleanly) << run.terminal;
  EXPECT_EQ(run.terminal.find('\r', error), std::string::npos) << run.terminal;
  EXPECT_TRUE(run.terminal.ends_with("\n")) << run.terminal;
  EXPECT_FALSE(std::filesystem::exists(scratch.file("out.ply")));
}

TEST(CliProgress, RemeshShowsItsRuns) {
  const test::ScratchDir scratch("progress-remesh");
  const TerminalRun run = run_on_terminal({"remesh", test::data_path("bunny_uniform.off").string(),
                                           scratch.file("out.ply").string(), "--target-vertices", "4000", "--json"},
                                          {"VERTEXFLOW_PROGRESS_DELAY=0"});
  ASSERT_EQ(run.exit_code, 0) << run.terminal;
  const TerminalPieces pieces = take_apart(run.terminal);
  EXPECT_TRUE(std::any_of(pieces.drawings.begin(), pieces.drawings.end(), [](const std::string& d) {
    return d.starts_with("vertexflow: remesh run 1  ");
  })) << run.terminal;
  EXPECT_TRUE(pieces.ends_cleanly) << run.terminal;
  // The JSON on stdout (the same terminal) is whole: the line was cleared before it.
  const std::size_t json = run.terminal.find("{\n");
  ASSERT_NE(json, std::string::npos) << run.terminal;
  EXPECT_TRUE(run.terminal.substr(0, json).ends_with("\n") || run.terminal.substr(0, json).ends_with(kClear));
  EXPECT_EQ(run.terminal.find('\r', json), std::string::npos) << run.terminal;
}

// The engine's reports: every phase of the flow, in order, within [0, 1], and the same result
// bytes with and without a sink.
TEST(Progress, EnhanceReportsItsPhasesInOrderAndChangesNothing) {
  const Mesh mesh = read_mesh(test::data_path("bunny_uniform.off"));
  const EnhanceResult quiet = enhance(mesh, nullptr, EnhanceOptions{});
  std::vector<std::string> phases;
  std::vector<double> begins, ends;
  EnhanceResult reported;
  {
    const ProgressScope scope([&](const Progress& p) {
      phases.emplace_back(p.phase);
      begins.push_back(p.begin);
      ends.push_back(p.end);
    });
    reported = enhance(mesh, nullptr, EnhanceOptions{});
  }
  EXPECT_EQ(reported.mesh.V, quiet.mesh.V);
  const std::vector<std::string> expected{"preparing", "flow",       "flow set-up", "curvature",
                                          "solve",     "projection", "guard"};
  // The solve reports every few iterations (flow_solver.cpp): bunny_uniform's 80 iterations
  // give 9 reports of "solve", the part's own and one per 10 iterations.
  std::vector<std::string> distinct = phases;
  distinct.erase(std::unique(distinct.begin(), distinct.end()), distinct.end());
  EXPECT_EQ(distinct, expected);
  EXPECT_GE(std::count(phases.begin(), phases.end(), "solve"), 5);
  for (std::size_t i = 0; i < phases.size(); ++i) {
    EXPECT_GE(begins[i], 0);
    EXPECT_LE(begins[i], ends[i]);
    EXPECT_LE(ends[i], 1);
    if (i > 0) {
      EXPECT_GE(begins[i], begins[i - 1]) << phases[i];
    }
  }
  EXPECT_EQ(begins.front(), 0);
  EXPECT_EQ(ends.back(), 1);
  // Outside the scope nothing reaches the sink.
  const std::size_t count = phases.size();
  (void)enhance(mesh, nullptr, EnhanceOptions{});
  EXPECT_EQ(phases.size(), count);
}

TEST(Progress, PartsNest) {
  std::vector<Progress> seen;
  std::vector<std::string> names;
  {
    const ProgressScope scope([&](const Progress& p) {
      seen.push_back(p);
      names.emplace_back(p.phase);
    });
    report_progress("reading", 0, 0.1);
    {
      const ProgressPart part("engine", 0.1, 0.9);
      report_progress("inner", 0.5, 1);
      const ProgressPart inner("", 0, 0.5);  // no report of its own
      report_progress("innermost", 0, 1);
    }
    report_progress("writing", 0.9, 2);  // clamped to 1
  }
  ASSERT_EQ(names, (std::vector<std::string>{"reading", "engine", "inner", "innermost", "writing"}));
  EXPECT_DOUBLE_EQ(seen[1].begin, 0.1);
  EXPECT_DOUBLE_EQ(seen[1].end, 0.9);
  EXPECT_DOUBLE_EQ(seen[2].begin, 0.5);
  EXPECT_DOUBLE_EQ(seen[2].end, 0.9);
  EXPECT_DOUBLE_EQ(seen[3].begin, 0.1);
  EXPECT_DOUBLE_EQ(seen[3].end, 0.5);
  EXPECT_DOUBLE_EQ(seen[4].begin, 0.9);
  EXPECT_DOUBLE_EQ(seen[4].end, 1.0);
}

}  // namespace
}  // namespace vertexflow
