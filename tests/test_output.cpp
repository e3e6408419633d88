// The one output writer (vdyn/core/file_io.h) on a full disk: /dev/full (ENOSPC
// on every write, so these always run) and, where the machine allows a mount,
// a real 64 KiB tmpfs. `vdyn run` and `vdyn sweep` on a full disk exit non-zero
// with one line naming the file and the system's reason, and print no
// "written" line for a file that was not written.
#include <gtest/gtest.h>

#include <sys/mount.h>
#include <sys/statvfs.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "test_util.h"
#include "vdyn/core/file_io.h"

namespace fs = std::filesystem;
using vdyn::test::errorOf;

namespace {

std::string readText(const std::string& path) {
  std::ifstream f(path);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

/// A fresh folder under the test output folder.
std::string freshDir(const std::string& name) {
  const std::string d = std::string(VDYN_TEST_OUT_DIR) + "/output_" + name;
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

struct Ran {
  int rc = -1;
  std::string out, err;
};

/// Runs `vdyn ARGS` (a shell command tail) with stdout and stderr captured.
Ran runVdyn(const std::string& args, const std::string& dir) {
  const std::string cmd = std::string("'") + VDYN_BIN + "' " + args + " > '" + dir + "/stdout.txt' 2> '" + dir +
                          "/stderr.txt'";
  const int st = std::system(cmd.c_str());
  Ran r;
  r.rc = WIFEXITED(st) ? WEXITSTATUS(st) : 128 + WTERMSIG(st);
  r.out = readText(dir + "/stdout.txt");
  r.err = readText(dir + "/stderr.txt");
  return r;
}

int lines(const std::string& s) { return int(std::count(s.begin(), s.end(), '\n')); }

/// A 64 KiB tmpfs mounted on a fresh folder, unmounted at the end; `reason`
/// says why not when the machine does not permit the mount.
struct Tmpfs {
  std::string dir, reason;
  bool mounted = false;
  explicit Tmpfs(const std::string& name, const char* size = "size=64k") : dir(freshDir(name) + "/fs") {
    fs::create_directories(dir);
    if (::mount("tmpfs", dir.c_str(), "tmpfs", 0, size) == 0)
      mounted = true;
    else
      reason = std::string("mount -t tmpfs -o ") + size + " not permitted here (" + std::strerror(errno) +
               "; needs root or CAP_SYS_ADMIN)";
  }
  ~Tmpfs() {
    if (mounted) ::umount2(dir.c_str(), MNT_DETACH);
  }
  double freeBytes() const {
    struct statvfs s {};
    ::statvfs(dir.c_str(), &s);
    return double(s.f_bavail) * double(s.f_bsize);
  }
};

}  // namespace

// The temporary file is /dev/full: every write fails with ENOSPC.
TEST(Writer, DevFullIsNamedErrorAndKeepsTheOldFile) {
  const std::string d = freshDir("devfull_unit"), path = d + "/summary.json";
  vdyn::writeFileAtomic(path, "old\n");
  fs::create_symlink("/dev/full", path + ".tmp");
  EXPECT_EQ(errorOf([&] { vdyn::writeFileAtomic(path, std::string(10000, 'x')); }),
            "cannot write '" + path + "': write failed: No space left on device (nothing written)");
  EXPECT_EQ(readText(path), "old\n");                 // the old file is untouched
  EXPECT_FALSE(fs::is_symlink(path + ".tmp"));        // the temporary name is removed
  vdyn::writeFileAtomic(path, "new\n");               // and the next write works
  EXPECT_EQ(readText(path), "new\n");
}

TEST(Writer, UnwritableFolderIsNamedError) {
  const std::string path = "/proc/vdyn_no_such_dir/x.csv";
  EXPECT_EQ(errorOf([&] { vdyn::writeFileAtomic(path, "a\n"); }),
            "cannot write '" + path + "': No such file or directory (nothing written)");
}

TEST(Writer, OutputFileWritesOnlyOnCommit) {
  const std::string d = freshDir("outputfile"), path = d + "/t.csv";
  {
    vdyn::OutputFile f(path);
    f << "a,b\n" << 1.5 << ',' << 2 << '\n';
  }
  EXPECT_FALSE(fs::exists(path));  // never committed: not written
  vdyn::OutputFile f(path);
  f << "a,b\n" << 1.5 << ',' << 2 << '\n';
  f.commit();
  EXPECT_EQ(readText(path), "a,b\n1.5,2\n");
}

TEST(Writer, AppendFileDevFullIsNamedError) {
  const std::string d = freshDir("devfull_append"), path = d + "/runs.jsonl";
  fs::create_symlink("/dev/full", path);
  vdyn::AppendFile f(path, true);
  EXPECT_EQ(errorOf([&] { f.appendLine("{\"variation\": 0}"); }),
            "cannot append to '" + path + "': write failed: No space left on device");
}

TEST(Writer, AppendFileClosesACutLine) {
  const std::string d = freshDir("append_cut"), path = d + "/runs.jsonl";
  vdyn::writeFileAtomic(path, "{\"a\": 1}\n{\"b\"");
  {
    vdyn::AppendFile f(path, true);
    f.appendLine("{\"c\": 3}");
    f.close();
  }
  EXPECT_EQ(readText(path), "{\"a\": 1}\n{\"b\"\n{\"c\": 3}\n");
}

// A real full file system: 64 KiB of tmpfs.
TEST(Writer, TmpfsFullIsNamedErrorAndLeavesNothing) {
  Tmpfs t("tmpfs_unit");
  if (!t.mounted) GTEST_SKIP() << t.reason;
  const std::string path = t.dir + "/history.csv";
  EXPECT_EQ(errorOf([&] { vdyn::writeFileAtomic(path, std::string(200000, 'x')); }),
            "cannot write '" + path + "': write failed: No space left on device (nothing written)");
  EXPECT_TRUE(fs::is_empty(t.dir));  // neither the file nor its temporary
  EXPECT_EQ(t.freeBytes(), 65536.0);
  vdyn::writeFileAtomic(path, std::string(10000, 'x'));
  EXPECT_EQ(fs::file_size(path), 10000u);
}

// vdyn run, the summary's temporary file on /dev/full.
TEST(VdynRun, DevFullSummaryExitsNonZeroNamingThePath) {
  const std::string d = freshDir("run_devfull"), out = d + "/out";
  fs::create_directories(out);
  fs::create_symlink("/dev/full", out + "/summary.json.tmp");
  const Ran r = runVdyn("run scenes/quarter_car_sine_road.json --no-plots --set analysis.t_end_s=0.05 --out '" + out + "'", d);
  EXPECT_EQ(r.rc, 1);
  EXPECT_EQ(r.err, "vdyn run: error: cannot write '" + out +
                       "/summary.json': write failed: No space left on device (nothing written)\n");
  EXPECT_EQ(r.out.find("summary.json"), std::string::npos) << r.out;  // no "written" line
  EXPECT_FALSE(fs::exists(out + "/summary.json"));
  EXPECT_TRUE(fs::exists(out + "/history.csv"));
}

TEST(VdynRun, DevFullTableExitsNonZeroNamingThePath) {
  const std::string d = freshDir("run_devfull_csv"), out = d + "/out";
  fs::create_directories(out);
  fs::create_symlink("/dev/full", out + "/history.csv.tmp");
  const Ran r = runVdyn("run scenes/quarter_car_sine_road.json --no-plots --set analysis.t_end_s=0.05 --out '" + out + "'", d);
  EXPECT_EQ(r.rc, 1);
  EXPECT_EQ(r.err, "vdyn run: error: cannot write '" + out +
                       "/history.csv': write failed: No space left on device (nothing written)\n");
  EXPECT_EQ(r.out.find("summary.json"), std::string::npos) << r.out;
  EXPECT_FALSE(fs::exists(out + "/summary.json"));
}

// vdyn run on a real full disk: room for history.csv but not for summary.json
// (the case, which exited 0 with a 0-byte summary.json).
TEST(VdynRun, TmpfsRoomForHistoryNotSummary) {
  const std::string ref = freshDir("run_tmpfs_ref");
  const std::string args = "run scenes/quarter_car_sine_road.json --no-plots --set analysis.t_end_s=0.05 --out ";
  ASSERT_EQ(runVdyn(args + "'" + ref + "/out'", ref).rc, 0);
  const auto history = fs::file_size(ref + "/out/history.csv");
  Tmpfs t("run_tmpfs", "size=256k");
  if (!t.mounted) GTEST_SKIP() << t.reason;
  const std::string out = t.dir + "/out";
  fs::create_directories(out);
  // Fill the disk to leave exactly the pages history.csv needs.
  const double page = 4096, need = std::ceil(double(history) / page) * page;
  { std::ofstream(t.dir + "/filler") << std::string(std::size_t(t.freeBytes() - need), 'f'); }
  ASSERT_EQ(t.freeBytes(), need);
  const std::string d = freshDir("run_tmpfs_logs");
  const Ran r = runVdyn(args + "'" + out + "'", d);
  EXPECT_EQ(r.rc, 1);
  EXPECT_EQ(r.err, "vdyn run: error: cannot write '" + out +
                       "/summary.json': write failed: No space left on device (nothing written)\n");
  EXPECT_EQ(r.out.find("summary.json"), std::string::npos) << r.out;
  EXPECT_FALSE(fs::exists(out + "/summary.json"));
  EXPECT_FALSE(fs::exists(out + "/summary.json.tmp"));
  EXPECT_EQ(fs::file_size(out + "/history.csv"), history);
}

// vdyn sweep: results.csv and the journal on /dev/full.
TEST(VdynSweep, DevFullResultsAndJournalExitNonZeroNamingThePath) {
  const std::string sweep = std::string(VDYN_TEST_DATA_DIR) + "/small.sweep.json";
  {
    const std::string d = freshDir("sweep_devfull"), out = d + "/out";
    fs::create_directories(out);
    fs::create_symlink("/dev/full", out + "/results.csv.tmp");
    const Ran r = runVdyn("sweep '" + sweep + "' --threads 1 --quiet --no-plots --out '" + out + "'", d);
    EXPECT_EQ(r.rc, 1);
    EXPECT_EQ(r.err, "vdyn sweep: error: cannot write '" + out +
                         "/results.csv': write failed: No space left on device (nothing written)\n");
    EXPECT_EQ(r.out.find("results.csv"), std::string::npos) << r.out;
    EXPECT_FALSE(fs::exists(out + "/results.csv"));
  }
  {
    const std::string d = freshDir("sweep_devfull_journal"), out = d + "/out";
    fs::create_directories(out);
    fs::create_symlink("/dev/full", out + "/runs.jsonl");  // --fresh: /dev/full reads as endless zeros
    const Ran r = runVdyn("sweep '" + sweep + "' --fresh --threads 1 --quiet --no-plots --out '" + out + "'", d);
    EXPECT_EQ(r.rc, 1);
    EXPECT_EQ(r.err, "vdyn sweep: error: cannot append to '" + out +
                         "/runs.jsonl': write failed: No space left on device\n");
    EXPECT_EQ(lines(r.err), 1);
    EXPECT_FALSE(fs::exists(out + "/results.csv"));
  }
}
