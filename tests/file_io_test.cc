// WriteFileAtomically under signals (lib/include/camproj/file_io.h, docs/reliability.md): a
// process killed by SIGINT, SIGTERM or SIGHUP while its threads replace files leaves every file
// whole and no temporary, and dies of the signal.
#include "camproj/file_io.h"

#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "camproj/errors.h"
#include "seeds.h"
#include "write_until_killed.h"

extern char** environ;

namespace camproj {
namespace {

namespace fs = std::filesystem;
using testing::ExpectRate;
using testing::Seed;

constexpr int kWriterThreads = 3;

// Runs write_until_killed in `folder` (with CAMPROJ_TEST_NO_TMPFILE set where `named`), waits
// for its first file, sleeps `delay`, sends `signal_number` and returns the wait status.
int KillWriters(const fs::path& folder, bool named, int signal_number,
                std::chrono::microseconds delay) {
  std::vector<std::string> env_strings;
  for (char** e = environ; *e != nullptr; ++e) {
    if (std::string(*e).rfind("CAMPROJ_TEST_NO_TMPFILE=", 0) != 0) env_strings.push_back(*e);
  }
  if (named) env_strings.push_back("CAMPROJ_TEST_NO_TMPFILE=1");
  std::vector<char*> env;
  for (std::string& s : env_strings) env.push_back(s.data());
  env.push_back(nullptr);
  std::string program = CAMPROJ_WRITE_UNTIL_KILLED;
  std::string folder_arg = folder.string();
  std::string threads_arg = std::to_string(kWriterThreads);
  char* argv[] = {program.data(), folder_arg.data(), threads_arg.data(), nullptr};
  // The handled signals at their default in the child (a test runner may ignore SIGINT or
  // SIGHUP, and the handlers leave an ignored signal ignored).
  posix_spawnattr_t attributes;
  posix_spawnattr_init(&attributes);
  sigset_t defaults;
  sigemptyset(&defaults);
  for (int s : {SIGINT, SIGTERM, SIGHUP}) sigaddset(&defaults, s);
  posix_spawnattr_setsigdefault(&attributes, &defaults);
  sigset_t none;
  sigemptyset(&none);
  posix_spawnattr_setsigmask(&attributes, &none);
  posix_spawnattr_setflags(&attributes, POSIX_SPAWN_SETSIGDEF | POSIX_SPAWN_SETSIGMASK);
  pid_t pid = -1;
  const int spawned = posix_spawn(&pid, program.c_str(), nullptr, &attributes, argv, env.data());
  posix_spawnattr_destroy(&attributes);
  if (spawned != 0) {
    ADD_FAILURE() << "cannot start " << program;
    return -1;
  }
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  int status = 0;
  while (!fs::exists(folder / "w0.json")) {
    if (waitpid(pid, &status, WNOHANG) == pid) {
      ADD_FAILURE() << program << " ended before writing";
      return status;
    }
    if (std::chrono::steady_clock::now() > deadline) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  std::this_thread::sleep_for(delay);
  kill(pid, signal_number);
  waitpid(pid, &status, 0);
  return status;
}

// Several hundred kills at random moments of three threads' replacing writes, with and without
// O_TMPFILE, cycling through the three signals. Before the handler waited for every open
// creation window and blocked the signals inside them (session 37), 9 % of such kills left a
// .camproj-*.tmp (46 of 500 with O_TMPFILE, 23 of 300 without) and some died of an uncaught
// "rename: No such file" instead of the signal; the property has no allowed rate (p = 0).
TEST(FileIoTest, SignalDuringWritesLeavesWholeFilesAndNoTemporary) {
  const fs::path root =
      fs::temp_directory_path() / ("camproj_file_io_kill_" + std::to_string(getpid()));
  const std::string contents = testing::WrittenContents();
  const int signals[] = {SIGTERM, SIGHUP, SIGINT};
  constexpr int kRoundsPerMode = 150;
  for (const bool named : {false, true}) {
    int failures = 0;
    for (int round = 0; round < kRoundsPerMode; ++round) {
      const fs::path folder = root / std::to_string(round);
      fs::create_directories(folder);
      std::mt19937_64 random(Seed(static_cast<uint64_t>(round) + (named ? 1000u : 0u)));
      const std::chrono::microseconds delay(std::uniform_int_distribution<int>(0, 5000)(random));
      const int signal_number = signals[round % 3];
      const int status = KillWriters(folder, named, signal_number, delay);
      bool ok = WIFSIGNALED(status) && WTERMSIG(status) == signal_number;
      EXPECT_TRUE(ok) << "round " << round << (named ? " (named)" : "") << ": status " << status
                      << ", not killed by signal " << signal_number;
      for (const fs::directory_entry& entry : fs::directory_iterator(folder)) {
        const std::string name = entry.path().filename().string();
        const bool writer_file = name.size() == 7 && name[0] == 'w' && name.substr(2) == ".json";
        if (!writer_file) {
          ok = false;
          ADD_FAILURE() << "round " << round << (named ? " (named)" : "") << ", signal "
                        << signal_number << " after " << delay.count() << " us: left " << name;
        } else if (ReadWholeFile(entry.path().string()) != contents) {
          ok = false;
          ADD_FAILURE() << "round " << round << ": " << name << " is not the whole file";
        }
      }
      failures += ok ? 0 : 1;
      fs::remove_all(folder);
    }
    ExpectRate(named ? "kills leaving a temporary or a partial file (no O_TMPFILE)"
                     : "kills leaving a temporary or a partial file (O_TMPFILE)",
               failures, kRoundsPerMode, 0.0);
  }
  fs::remove_all(root);
}

// A fresh folder under the temporary directory, removed at the end of the test.
class TemporaryFolder {
 public:
  explicit TemporaryFolder(const std::string& name)
      : path_(fs::temp_directory_path() / (name + "_" + std::to_string(getpid()))) {
    fs::remove_all(path_);
    fs::create_directories(path_);
  }
  ~TemporaryFolder() { fs::remove_all(path_); }
  const fs::path& path() const { return path_; }
  // The names in the folder, sorted.
  std::vector<std::string> Names() const {
    std::vector<std::string> names;
    for (const fs::directory_entry& e : fs::directory_iterator(path_)) {
      names.push_back(e.path().filename().string());
    }
    std::sort(names.begin(), names.end());
    return names;
  }

 private:
  fs::path path_;
};

TEST(FileIoTest, SameFileResolvesDotsLinksAndHardLinks) {
  const TemporaryFolder folder("camproj_same_file");
  const fs::path& d = folder.path();
  fs::create_directories(d / "sub");
  fs::create_directory_symlink(d / "sub", d / "link");
  const std::string a = (d / "a.json").string();
  EXPECT_TRUE(SameFile(a, (d / "sub" / ".." / "a.json").string()));  // neither exists
  EXPECT_TRUE(SameFile((d / "link" / "c.json").string(), (d / "sub" / "c.json").string()));
  EXPECT_FALSE(SameFile(a, (d / "b.json").string()));
  WriteFileAtomically(a, "a");
  fs::create_hard_link(a, d / "hard.json");
  EXPECT_TRUE(SameFile(a, (d / "hard.json").string()));
  fs::create_symlink(a, d / "soft.json");
  EXPECT_TRUE(SameFile((d / "soft.json").string(), a));
  // A relative path and its absolute form.
  const fs::path before = fs::current_path();
  fs::current_path(d);
  EXPECT_TRUE(SameFile("./x.json", (d / "x.json").string()));
  EXPECT_TRUE(SameFile("x.json", "./x.json"));
  fs::current_path(before);
}

// An empty path is refused as such, not with the errno of open("") or link("").
TEST(FileIoTest, AnEmptyPathIsRefusedAsEmpty) {
  try {
    WriteFileAtomically("", "x");
    ADD_FAILURE() << "wrote";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "cannot write a file with an empty path");
  }
}

TEST(FileIoTest, WriteFilesAtomicallyWritesAllOrNone) {
  const TemporaryFolder folder("camproj_write_files");
  const fs::path& d = folder.path();
  const std::string first = (d / "first.json").string();
  const std::string second = (d / "second.csv").string();
  WriteFilesAtomically({{first, "one", "-o"}, {second, "two", "--poses"}});
  EXPECT_EQ(ReadWholeFile(first), "one");
  EXPECT_EQ(ReadWholeFile(second), "two");
  // The second cannot be written (its folder does not exist): the first keeps its old
  // contents, a new first output is not created, and no temporary is left.
  const std::string missing = (d / "missing" / "x.csv").string();
  for (const bool named : {false, true}) {
    if (named) setenv("CAMPROJ_TEST_NO_TMPFILE", "1", 1);
    EXPECT_THROW(WriteFilesAtomically({{first, "changed", "-o"}, {missing, "x", "--poses"}}),
                 InputError);
    EXPECT_THROW(WriteFilesAtomically({{(d / "new.json").string(), "new", "-o"},
                                       {missing, "x", "--poses"}}),
                 InputError);
    if (named) unsetenv("CAMPROJ_TEST_NO_TMPFILE");
    EXPECT_EQ(ReadWholeFile(first), "one");
    EXPECT_EQ(folder.Names(), (std::vector<std::string>{"first.json", "second.csv"}));
  }
  // Two outputs naming one file: refused before anything is written, naming both.
  try {
    WriteFilesAtomically({{(d / "n.json").string(), "a", "-o"},
                          {(d / "." / "n.json").string(), "b", "--truth"}});
    ADD_FAILURE() << "two outputs naming one file were written";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("-o and --truth both name"), std::string::npos) << e.what();
  }
  EXPECT_EQ(folder.Names(), (std::vector<std::string>{"first.json", "second.csv"}));
}

}  // namespace
}  // namespace camproj
