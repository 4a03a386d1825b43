// SPDX-License-Identifier: MIT
// Crash-safe files and diverging scenes through the `tgraph` command line: captures and
// replays killed with SIGKILL at random moments, writes that hit the file size limit (as a
// full disk would), scenes whose time step or stiffness the integrators cannot handle.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <optional>
#include <random>
#include <regex>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "tgraph/graph/error.hpp"
#include "tgraph/graph/file_util.hpp"
#include "tgraph/graph/timeline.hpp"
#include "tgraph/graph/trace_io.hpp"
#include "tgraph/partition/assignment_io.hpp"
#include "../scratch_dir.hpp"

namespace tgraph {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

std::string slurp(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

void write(const fs::path& p, const std::string& text) {
  std::ofstream(p, std::ios::binary) << text;
}

// One started `tgraph` process.
struct Child {
  pid_t pid = -1;
};

// Starts `tgraph args...` in `dir` with stdout/stderr to dir/stdout and dir/stderr, under
// a file size limit when given (SIGXFSZ ignored: write() then fails with EFBIG).
Child spawn(const fs::path& dir, const std::vector<std::string>& args,
            std::optional<rlim_t> fsize = std::nullopt) {
  std::vector<std::string> argv_s = {TGRAPH_BIN};
  argv_s.insert(argv_s.end(), args.begin(), args.end());
  const std::string out = (dir / "stdout").string(), err = (dir / "stderr").string();
  const pid_t pid = ::fork();
  if (pid == 0) {
    if (::chdir(dir.c_str()) != 0) std::_Exit(120);
    if (std::freopen(out.c_str(), "w", stdout) == nullptr) std::_Exit(121);
    if (std::freopen(err.c_str(), "w", stderr) == nullptr) std::_Exit(122);
    if (fsize) {
      ::signal(SIGXFSZ, SIG_IGN);
      rlimit limit{*fsize, *fsize};
      if (::setrlimit(RLIMIT_FSIZE, &limit) != 0) std::_Exit(123);
    }
    std::vector<char*> argv;
    for (std::string& a : argv_s) argv.push_back(a.data());
    argv.push_back(nullptr);
    ::execv(argv[0], argv.data());
    std::_Exit(124);
  }
  return Child{pid};
}

// Waits for the child; its exit status, or 128 + signal.
int finish(const Child& c) {
  int status = 0;
  ::waitpid(c.pid, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

// True while the child runs (reaps it when it has ended; `code` then holds its status).
bool running(const Child& c, int& code) {
  int status = 0;
  const pid_t r = ::waitpid(c.pid, &status, WNOHANG);
  if (r == 0) return true;
  code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  return false;
}

class Files : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = tgraph::test::scratch_dir("tgraph_robust_");
  }
  void TearDown() override { fs::remove_all(dir_); }

  int run(const std::vector<std::string>& args, std::optional<rlim_t> fsize = std::nullopt) {
    return finish(spawn(dir_, args, fsize));
  }
  std::string err() const { return slurp(dir_ / "stderr"); }

  // Files of dir_ other than the given ones and the child's stdout/stderr.
  std::vector<std::string> others(const std::vector<std::string>& known) const {
    std::vector<std::string> v;
    for (const auto& e : fs::directory_iterator(dir_)) {
      const std::string n = e.path().filename().string();
      if (n == "stdout" || n == "stderr") continue;
      if (std::find(known.begin(), known.end(), n) == known.end()) v.push_back(n);
    }
    return v;
  }

  fs::path dir_;
};

std::vector<std::uint64_t> step_hashes(const Trace& t) {
  std::vector<std::uint64_t> h;
  for (const StepGraph& g : t.steps) h.push_back(g.structural_hash());
  return h;
}

// 100 captures killed with SIGKILL at random moments (half at a random time, half once the
// partial file reached a random size): the output is the old file or the whole new trace,
// never a part; the partial file, when there is one, reads back with --recover as a prefix
// of the steps a complete capture writes.
TEST_F(Files, CaptureKilledAtRandomMomentsLeavesTheOldFileAndRecoverableSteps) {
  const std::vector<std::string> capture = {"capture", "--scene", "falling", "--steps",
                                            "30",      "-o",      "out.tgt"};
  // The reference: a complete capture (same scene and seed: same structures).
  const auto t0 = Clock::now();
  ASSERT_EQ(run(capture), 0) << err();
  const auto full = Clock::now() - t0;
  const Trace reference = read_trace((dir_ / "out.tgt").string());
  const std::vector<std::uint64_t> ref_hashes = step_hashes(reference);
  const auto ref_size = fs::file_size(dir_ / "out.tgt");
  ASSERT_EQ(reference.steps.size(), 30u);
  // The "old" output: another trace.
  ASSERT_EQ(run({"capture", "--scene", "fig2", "--steps", "3", "-o", "old.tgt"}), 0) << err();
  const std::string old_bytes = slurp(dir_ / "old.tgt");

  std::mt19937_64 rng(20261123);
  int untouched = 0, replaced = 0, recovered = 0, recovered_steps = 0, no_partial = 0;
  for (int i = 0; i < 100; ++i) {
    fs::remove(dir_ / "out.tgt.partial");
    write(dir_ / "out.tgt", old_bytes);
    const Child c = spawn(dir_, capture);
    int code = -1;
    bool ended = false;
    if (i % 2 == 0) {
      const auto delay = std::chrono::duration_cast<std::chrono::microseconds>(full * 1.2) *
                         std::uniform_real_distribution<double>(0.0, 1.0)(rng);
      const auto until = Clock::now() + delay;
      while (Clock::now() < until && !ended) {
        ended = !running(c, code);
        std::this_thread::sleep_for(std::chrono::microseconds(200));
      }
    } else {
      const auto bytes = std::uniform_int_distribution<std::uintmax_t>(1, ref_size)(rng);
      std::error_code ec;
      while (!ended) {
        const auto size = fs::file_size(dir_ / "out.tgt.partial", ec);
        if (!ec && size >= bytes) break;
        ended = !running(c, code);
        std::this_thread::sleep_for(std::chrono::microseconds(100));
      }
    }
    if (!ended) {
      ::kill(c.pid, SIGKILL);
      code = finish(c);
    }
    ASSERT_TRUE(code == 0 || code == 128 + SIGKILL)
        << "kill " << i << ": exit " << code << " " << err();

    const std::string out_bytes = slurp(dir_ / "out.tgt");
    if (out_bytes == old_bytes) {
      ++untouched;
    } else {
      Trace t;
      ASSERT_NO_THROW(t = read_trace((dir_ / "out.tgt").string())) << "kill " << i;
      EXPECT_EQ(step_hashes(t), ref_hashes) << "kill " << i;
      ++replaced;
    }
    if (fs::exists(dir_ / "out.tgt.partial")) {
      ReadOptions recover;
      recover.recover = true;
      Trace t;
      ASSERT_NO_THROW(t = read_trace((dir_ / "out.tgt.partial").string(), recover))
          << "kill " << i << " (" << fs::file_size(dir_ / "out.tgt.partial") << " bytes)";
      EXPECT_EQ(t.header, reference.header) << "kill " << i;
      ASSERT_LE(t.steps.size(), ref_hashes.size());
      const std::vector<std::uint64_t> h = step_hashes(t);
      EXPECT_TRUE(std::equal(h.begin(), h.end(), ref_hashes.begin())) << "kill " << i;
      ++recovered;
      recovered_steps += static_cast<int>(t.steps.size());
    } else {
      ++no_partial;
    }
    // Nothing else is left behind but the partial file.
    EXPECT_EQ(others({"out.tgt", "out.tgt.partial", "old.tgt"}), std::vector<std::string>{})
        << "kill " << i;
  }
  std::printf(
      "100 kills: output untouched %d, replaced by the whole new trace %d; partial "
      "files recovered %d (%d steps in all), none left %d\n",
      untouched, replaced, recovered, recovered_steps, no_partial);
  EXPECT_GT(recovered, 0);
}

// A replay's timeline and a partition's assignment written over existing files: a kill at
// any moment leaves the old file or the new one.
TEST_F(Files, ReplayAndPartitionOutputsKilledAreTheOldFileOrTheNewOne) {
  ASSERT_EQ(run({"capture", "--scene", "bars64", "--steps", "4", "-o", "t.tgt"}), 0) << err();
  std::mt19937_64 rng(7);
  struct Writer {
    std::vector<std::string> args;
    std::string output;
  };
  const std::vector<Writer> writers = {
      {{"replay", "t.tgt", "--threads", "2", "--no-pin", "--repeat", "1", "--no-baseline",
        "--timeline", "out.json"},
       "out.json"},
      {{"partition", "t.tgt", "-m", "metis", "-k", "2", "-o", "out.tga"}, "out.tga"}};
  for (const Writer& wr : writers) {
    const auto t0 = Clock::now();
    ASSERT_EQ(run(wr.args), 0) << err();
    const auto full = Clock::now() - t0;
    const std::string new_bytes = slurp(dir_ / wr.output);
    const std::string old_bytes = "the old " + wr.output + "\n";
    int old_kept = 0, new_seen = 0;
    for (int i = 0; i < 10; ++i) {
      write(dir_ / wr.output, old_bytes);
      const Child c = spawn(dir_, wr.args);
      const auto delay = std::chrono::duration_cast<std::chrono::microseconds>(full * 1.2) *
                         std::uniform_real_distribution<double>(0.0, 1.0)(rng);
      std::this_thread::sleep_for(delay);
      ::kill(c.pid, SIGKILL);
      const int code = finish(c);
      ASSERT_TRUE(code == 0 || code == 128 + SIGKILL) << code;
      const std::string now = slurp(dir_ / wr.output);
      if (now == old_bytes) {
        ++old_kept;
      } else if (wr.output == "out.tga") {
        // A complete assignment of every step (METIS may choose another one each run).
        TraceAssignment a;
        ASSERT_NO_THROW(a = partition::read_assignment((dir_ / wr.output).string()))
            << wr.output << " kill " << i;
        EXPECT_EQ(a.steps.size(), 4u);
        ++new_seen;
      } else {
        // Timelines hold measured times: a complete file (gzip-compressed JSON) with every
        // task.
        tgraph::Timeline t;
        ASSERT_NO_THROW(t = tgraph::parse_timeline(now, "out.json")) << wr.output << " kill " << i;
        EXPECT_EQ(t.tasks.size(), tgraph::parse_timeline(new_bytes, "new.json").tasks.size());
        ++new_seen;
      }
      // A killed atomic write may leave its temporary file (.out.json.tmp.N, killed between
      // the link and the rename), never a partial output.
      for (const auto& e : fs::directory_iterator(dir_)) {
        const std::string n = e.path().filename().string();
        if (n.rfind("." + wr.output + ".tmp.", 0) == 0) fs::remove(e.path());
      }
    }
    EXPECT_EQ(old_kept + new_seen, 10);
  }
}

// write_file_atomic killed while it writes 32 MiB over an existing file: the file is
// always the old content or the new one, whole; and the bytes being written have no name
// yet (an unnamed file, linked under a temporary name only for the rename), so a kill
// leaves no temporary file (one is allowed for a kill between the link and the rename).
TEST_F(Files, AnAtomicWriteKilledMidWayLeavesTheOldOrTheNewContent) {
  const fs::path p = dir_ / "big.bin";
  const std::string a(32 << 20, 'a'), b(32 << 20, 'b');
  write_file_atomic(p.string(), a);
  std::mt19937_64 rng(11);
  int olds = 0, news = 0, left = 0;
  for (int i = 0; i < 20; ++i) {
    const pid_t pid = ::fork();
    ASSERT_GE(pid, 0);
    if (pid == 0) {
      try {
        for (;;) {
          write_file_atomic(p.string(), b);
          write_file_atomic(p.string(), a);
        }
      } catch (...) {
        std::_Exit(3);
      }
    }
    std::this_thread::sleep_for(
        std::chrono::microseconds(std::uniform_int_distribution<int>(0, 200000)(rng)));
    ::kill(pid, SIGKILL);
    int status = 0;
    ::waitpid(pid, &status, 0);
    ASSERT_TRUE(WIFSIGNALED(status));
    const std::string now = slurp(p);
    ASSERT_TRUE(now == a || now == b) << "kill " << i << ": " << now.size() << " bytes";
    (now == a ? olds : news) += 1;
    for (const auto& e : fs::directory_iterator(dir_))
      if (e.path() != p) {
        ++left;
        fs::remove(e.path());
      }
  }
  EXPECT_EQ(olds + news, 20);
  EXPECT_LE(left, 1) << "temporary files left by 20 kills";
}

// A capture that runs out of room (RLIMIT_FSIZE) stops with exit 1 and a one-line error
// naming the partial file, which reads back with --recover; an existing output is kept.
TEST_F(Files, CaptureOnAFullDiskStopsWithAClearErrorAndKeepsItsSteps) {
  ASSERT_EQ(run({"capture", "--scene", "falling", "--steps", "300", "-o", "ref.tgt"}), 0) << err();
  const std::vector<std::uint64_t> ref = step_hashes(read_trace((dir_ / "ref.tgt").string()));
  write(dir_ / "out.tgt", "old output\n");
  const int code =
      run({"capture", "--scene", "falling", "--steps", "300", "-o", "out.tgt"}, rlim_t{60000});
  EXPECT_EQ(code, 1);
  const std::string e = err();
  EXPECT_TRUE(std::regex_search(
      e, std::regex("^tgraph: capture: step [0-9]+: out\\.tgt\\.partial: cannot write: File too "
                    "large; the [0-9]+ complete steps before it are in out\\.tgt\\.partial \\(read "
                    "with --recover\\)\n$")))
      << e;
  EXPECT_EQ(slurp(dir_ / "out.tgt"), "old output\n");
  EXPECT_LE(fs::file_size(dir_ / "out.tgt.partial"), 60000u);
  ReadOptions recover;
  recover.recover = true;
  const Trace t = read_trace((dir_ / "out.tgt.partial").string(), recover);
  ASSERT_GT(t.steps.size(), 0u);
  ASSERT_LT(t.steps.size(), ref.size());
  const std::vector<std::uint64_t> h = step_hashes(t);
  EXPECT_TRUE(std::equal(h.begin(), h.end(), ref.begin()));
  EXPECT_NE(e.find("the " + std::to_string(t.steps.size()) + " complete steps"), std::string::npos)
      << e;
  // `info --recover` reads it on the command line too.
  EXPECT_EQ(run({"info", "--recover", "out.tgt.partial"}), 0) << err();
}

// Whole-file writers (assignment, report, timeline) that run out of room fail with a
// message naming the file, keep the old file and leave no temporary file behind.
TEST_F(Files, WritersOnAFullDiskKeepTheOldFile) {
  ASSERT_EQ(run({"capture", "--scene", "falling", "--steps", "20", "-o", "t.tgt"}), 0) << err();
  const struct {
    std::vector<std::string> args;
    std::string output;
  } writers[] = {{{"partition", "t.tgt", "-m", "owner", "-k", "2", "-o", "out.tga"}, "out.tga"},
                 {{"replay", "t.tgt", "--threads", "2", "--no-pin", "--repeat", "1",
                   "--no-baseline", "--timeline", "out.json"},
                  "out.json"},
                 {{"export", "t.tgt", "--format", "json", "-o", "out.json"}, "out.json"}};
  for (const auto& wr : writers) {
    write(dir_ / wr.output, "old\n");
    const int code = run(wr.args, rlim_t{4096});
    EXPECT_NE(code, 0) << wr.output;
    const std::string e = err();
    EXPECT_NE(e.find(wr.output), std::string::npos) << e;
    EXPECT_NE(e.find("File too large"), std::string::npos) << e;
    EXPECT_EQ(std::count(e.begin(), e.end(), '\n'), 1) << e;
    EXPECT_EQ(slurp(dir_ / wr.output), "old\n") << wr.output;
    EXPECT_EQ(others({"t.tgt", wr.output}), std::vector<std::string>{}) << wr.output;
    fs::remove(dir_ / wr.output);
  }
}

// An assignment made for another trace, with a processor >= k, or for another thread
// count is refused (exit 2, one line naming the file) before anything is replayed.
TEST_F(Files, ReplayRefusesAnAssignmentThatDoesNotFitBeforeAnyThreadStarts) {
  ASSERT_EQ(run({"capture", "--scene", "fig2", "--steps", "2", "-o", "fig2.tgt"}), 0) << err();
  ASSERT_EQ(run({"capture", "--scene", "bars64", "--steps", "2", "-o", "bars.tgt"}), 0) << err();
  ASSERT_EQ(run({"partition", "fig2.tgt", "-m", "owner", "-k", "2", "-o", "fig2.tga"}), 0) << err();
  ASSERT_EQ(run({"partition", "bars.tgt", "-m", "owner", "-k", "2", "-o", "bars.tga"}), 0) << err();
  const auto refused = [&](const std::vector<std::string>& args, const std::string& starts) {
    const std::vector<std::string> base = {"replay", "fig2.tgt", "--no-pin", "--repeat", "1"};
    std::vector<std::string> all = base;
    all.insert(all.end(), args.begin(), args.end());
    EXPECT_EQ(run(all), 2) << starts;
    const std::string e = err();
    EXPECT_EQ(e.rfind("tgraph: " + starts, 0), 0u) << e;
    EXPECT_EQ(std::count(e.begin(), e.end(), '\n'), 1) << e;
    EXPECT_EQ(slurp(dir_ / "stdout"), "") << starts;  // nothing was replayed
  };
  // Another trace's assignment: its task counts do not fit.
  refused({"bars.tga", "--threads", "2"}, "bars.tga: step 0: ");
  // Same task counts, another structure (the stored hash of step 1 changed).
  std::vector<std::uint64_t> hashes;
  TraceAssignment a = partition::read_assignment((dir_ / "fig2.tga").string(), &hashes);
  ASSERT_EQ(hashes.size(), 2u);
  hashes[1] ^= 1;
  partition::write_assignment((dir_ / "other.tga").string(), a, hashes);
  refused({"other.tga", "--threads", "2"},
          "other.tga: step 1 was partitioned for a graph of another structure than fig2.tgt");
  // A processor >= k (the reader itself refuses it).
  a.steps[0].proc[0] = 7;
  partition::write_assignment((dir_ / "proc.tga").string(), a, hashes);
  refused({"proc.tga", "--threads", "2"},
          "proc.tga: offset 54: step 0: task 0 on processor 7, expected < k = 2");
  // k = 2 replayed on 3 threads.
  refused({"fig2.tga", "--threads", "3"}, "--threads: 3 does not fit fig2.tga: assignment has k = 2");
  // The fitting one replays.
  EXPECT_EQ(run({"replay", "fig2.tgt", "fig2.tga", "--threads", "2", "--no-pin", "--repeat", "1"}),
            0)
      << err();
}

// ---- scenes the integrators cannot handle ----------------------------------------------

std::string falling_with(const std::string& from, const std::string& to) {
  std::string s = slurp(fs::path(TGRAPH_SCENES) / "falling.scene");
  const auto at = s.find(from);
  if (at == std::string::npos) throw std::runtime_error("falling.scene has no " + from);
  return s.replace(at, from.size(), to);
}

TEST_F(Files, CaptureWithAHugeTimeStepExits1NamingTheStepAndObject) {
  write(dir_ / "dt.scene", falling_with("dt=0.005", "dt=1e308"));
  EXPECT_EQ(run({"capture", "--scene", "dt.scene", "-o", "out.tgt"}), 1);
  const std::string e = err();
  EXPECT_TRUE(std::regex_search(
      e, std::regex("\ntgraph: capture: simulation diverged at step 0: (position|velocity|force) "
                    "of '[a-z_0-9]+' is not finite \\(node [0-9]+: [^)]*\\); the 0 complete steps "
                    "before it are in out\\.tgt\\.partial \\(read with --recover\\)\n$")))
      << e;
  EXPECT_NE(e.find("warning: dt.scene:9: dt=1e+308 s"), std::string::npos) << e;
  EXPECT_FALSE(fs::exists(dir_ / "out.tgt"));
  ReadOptions recover;
  recover.recover = true;
  EXPECT_EQ(read_trace((dir_ / "out.tgt.partial").string(), recover).steps.size(), 0u);
}

TEST_F(Files, CaptureWithAnOverflowingStiffnessIsRefusedNamingTheLine) {
  write(dir_ / "young.scene", falling_with("young=2e5", "young=1e308"));
  EXPECT_EQ(run({"capture", "--scene", "young.scene", "-o", "out.tgt"}), 2);
  const std::string e = err();
  EXPECT_EQ(e.rfind("tgraph: young.scene:18: object 'cube': the stiffness overflows double "
                    "arithmetic",
                    0),
            0u)
      << e;
  EXPECT_EQ(std::count(e.begin(), e.end(), '\n'), 1) << e;
  EXPECT_FALSE(fs::exists(dir_ / "out.tgt"));
  EXPECT_FALSE(fs::exists(dir_ / "out.tgt.partial"));
}

TEST_F(Files, ReplayRefusesABadTimeout) {
  ASSERT_EQ(run({"capture", "--scene", "fig2", "--steps", "2", "-o", "t.tgt"}), 0) << err();
  EXPECT_EQ(run({"replay", "t.tgt", "--timeout", "-1"}), 2);
  EXPECT_NE(err().find("--timeout"), std::string::npos) << err();
  EXPECT_EQ(
      run({"replay", "t.tgt", "--threads", "2", "--no-pin", "--repeat", "1", "--timeout", "0.5"}),
      0)
      << err();
}

}  // namespace
}  // namespace tgraph
