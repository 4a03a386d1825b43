// SPDX-License-Identifier: MIT
// The process around the SimGrid engine of `tgraph simulate` (simgrid_engine.cpp runs the
// steps): SimGrid 3.32 allows one engine per process (a second one keeps the first one's
// clock and models) and ends the process on some malformed platform files, so a child
// process loads the platform and simulates, with its output sent to a temporary file, and
// hands the per-step results back through a pipe.
#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>
#include <xbt/log.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <simgrid/s4u.hpp>
#include <stdexcept>
#include <string>

#include "simgrid_engine.hpp"
#include "tgraph/graph/error.hpp"
#include "tgraph/graph/file_util.hpp"
#include "tgraph/model/simulation.hpp"

namespace tgraph::model::detail {

namespace {

namespace sg = simgrid::s4u;

// What the child hands back: a tag byte, then the payload.
constexpr char kLoaded = 'L', kResult = 'R', kInputError = 'I', kFailure = 'F';

void write_all(int fd, const void* data, std::size_t n) {
  const char* p = static_cast<const char*>(data);
  while (n > 0) {
    const ssize_t w = ::write(fd, p, n);
    if (w <= 0) return;
    p += w;
    n -= static_cast<std::size_t>(w);
  }
}

void send_message(int fd, char tag, const std::string& text) {
  write_all(fd, &tag, 1);
  write_all(fd, text.data(), text.size());
}

// The child: loads the platform, maps processors to hosts, simulates, writes the results.
[[noreturn]] void child(int fd, const Trace& trace, const TraceAssignment& a,
                        const SimulatedPlatform& platform) {
  int code = 0;
  try {
    std::string file = platform.file;
    std::string temp;
    if (file.empty()) {
      char name[] = "/tmp/tgraph-platform-XXXXXX";
      const int tfd = ::mkstemp(name);
      if (tfd < 0) throw std::runtime_error("cannot create a temporary platform file");
      ::close(tfd);
      temp = name;
      write_file_atomic(temp, platform_xml(*platform.cluster, platform.model));
      file = temp;
    }
    std::string program = "tgraph-simulate";
    char* argv[] = {program.data(), nullptr};
    int argc = 1;
    sg::Engine engine(&argc, argv);
    xbt_log_control_set("root.thresh:critical");
    for (std::string_view item : kSimgridNetworkConfig) sg::Engine::set_config(std::string(item));
    try {
      engine.load_platform(file);
    } catch (const std::exception& e) {
      if (!temp.empty()) ::unlink(temp.c_str());
      send_message(fd, kInputError,
                   "SimGrid cannot load this platform (" + std::string(e.what()) + ")");
      ::_exit(0);
    }
    if (!temp.empty()) ::unlink(temp.c_str());
    write_all(fd, &kLoaded, 1);

    const PlatformRun run = run_on_loaded_platform(trace, a, platform);
    if (!run.input_error.empty()) {
      send_message(fd, kInputError, run.input_error);
      ::_exit(0);
    }
    const std::uint64_t header[2] = {run.hosts, run.cores};
    write_all(fd, &kResult, 1);
    write_all(fd, header, sizeof header);
    for (const StepPrediction& s : run.steps) {
      const std::uint64_t v[5] = {s.makespan_ns, s.messages, s.bytes, s.inter_node_messages,
                                  s.inter_node_bytes};
      write_all(fd, v, sizeof v);
    }
  } catch (const std::exception& e) {
    send_message(fd, kFailure, e.what());
  } catch (...) {
    send_message(fd, kFailure, "SimGrid failed");
    code = 1;
  }
  ::_exit(code);
}

// The last non-empty line SimGrid wrote (its reason when it ended the child).
std::string last_line(std::FILE* f) {
  std::string text, line;
  std::fflush(f);
  std::rewind(f);
  char buf[4096];
  std::size_t n;
  while ((n = std::fread(buf, 1, sizeof buf, f)) > 0) text.append(buf, n);
  std::size_t end = text.find_last_not_of(" \n\r\t");
  if (end == std::string::npos) return "";
  const std::size_t begin = text.rfind('\n', end);
  return text.substr(begin == std::string::npos ? 0 : begin + 1,
                     end + 1 - (begin == std::string::npos ? 0 : begin + 1));
}

// One line: SimGrid's messages may span several.
std::string one_line(std::string text) {
  for (char& c : text)
    if (c == '\n' || c == '\r') c = ' ';
  return text;
}

}  // namespace

Prediction simgrid_predict(const Trace& trace, const TraceAssignment& a,
                           const SimulatedPlatform& platform) {
  if (!platform.file.empty()) (void)read_file_bytes(platform.file);  // missing: InputError
  int fds[2];
  if (::pipe(fds) != 0) throw std::runtime_error("simulate: cannot create a pipe");
  std::FILE* log = std::tmpfile();
  std::fflush(stdout);
  std::fflush(stderr);
  const pid_t pid = ::fork();
  if (pid < 0) {
    ::close(fds[0]);
    ::close(fds[1]);
    if (log) std::fclose(log);
    throw std::runtime_error("simulate: cannot start the SimGrid process");
  }
  if (pid == 0) {
    ::close(fds[0]);
    // SimGrid's own messages never reach tgraph's stdout (a JSON report there stays one object).
    const int out = log ? ::fileno(log) : ::open("/dev/null", O_WRONLY);
    ::dup2(out, STDOUT_FILENO);
    ::dup2(out, STDERR_FILENO);
    child(fds[1], trace, a, platform);
  }
  ::close(fds[1]);
  std::string got;
  char buf[1 << 16];
  for (;;) {
    const ssize_t n = ::read(fds[0], buf, sizeof buf);
    if (n > 0) {
      got.append(buf, static_cast<std::size_t>(n));
      continue;
    }
    if (n < 0 && errno == EINTR) continue;
    break;
  }
  ::close(fds[0]);
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  const std::string said = log ? one_line(last_line(log)) : "";
  if (log) std::fclose(log);
  const std::string where = platform.file.empty() ? "the cluster platform" : platform.file;
  const bool loaded = !got.empty() && got[0] == kLoaded;
  const std::string rest = loaded ? got.substr(1) : got;
  if (!rest.empty() && rest[0] == kInputError) {
    if (!loaded && !platform.file.empty())
      throw InputError(platform.file, std::nullopt, one_line(rest.substr(1)));
    throw Error(one_line(rest.substr(1)));
  }
  if (!rest.empty() && rest[0] == kFailure)
    throw std::runtime_error("simgrid: " + one_line(rest.substr(1)));
  const std::size_t step_bytes = 5 * sizeof(std::uint64_t);
  if (rest.empty() || rest[0] != kResult || rest.size() < 1 + 2 * sizeof(std::uint64_t) ||
      (rest.size() - 1 - 2 * sizeof(std::uint64_t)) % step_bytes != 0) {
    const std::string why =
        "SimGrid ended " +
        (WIFSIGNALED(status) ? "with signal " + std::to_string(WTERMSIG(status))
                             : "with status " + std::to_string(WEXITSTATUS(status))) +
        (said.empty() ? "" : ": " + said);
    if (!loaded && !platform.file.empty())
      throw InputError(platform.file, std::nullopt,
                       "SimGrid cannot load this platform (" + why + ")");
    throw std::runtime_error("simulate on " + where + ": " + why);
  }
  Prediction r;
  r.engine = SimulationEngine::simgrid;
  r.k = a.k;
  std::uint64_t header[2];
  std::memcpy(header, rest.data() + 1, sizeof header);
  r.hosts = static_cast<std::uint32_t>(header[0]);
  r.cores = header[1];
  r.platform = platform.file.empty() ? std::to_string(platform.cluster->nodes) + "x" +
                                           std::to_string(platform.cluster->cores)
                                     : platform.file;
  for (std::size_t at = 1 + sizeof header; at + step_bytes <= rest.size(); at += step_bytes) {
    std::uint64_t v[5];
    std::memcpy(v, rest.data() + at, sizeof v);
    r.steps.push_back({v[0], v[1], v[2], v[3], v[4]});
  }
  return r;
}

}  // namespace tgraph::model::detail
