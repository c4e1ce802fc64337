// Issue 33, bag_runner's files without a ROS master: outputs never touch inputs (the same path,
// a hard link, a symbolic link), temporary names that are hidden, never end in .png and are
// removed once their writer is gone, a folder that cannot be written named with the reason, and
// the manifest that tells one run from another.
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <string>

#include <gtest/gtest.h>

#include "bag_runner/bag_files.h"
#include "bag_runner/bag_manifest.h"

namespace fs = std::filesystem;
namespace lsf = lidar_stereo_fusion;

namespace {

/// A fresh scratch folder in the build folder.
fs::path scratch(const std::string& name) {
  const fs::path dir = fs::path(LSF_BINARY_DIR) / "test_bag_files" / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

void write(const fs::path& path, const std::string& text) { std::ofstream(path) << text; }

/// A process id that runs nothing: a child that has exited and been reaped.
long deadPid() {
  const pid_t pid = ::fork();
  if (pid == 0) ::_exit(0);
  ::waitpid(pid, nullptr, 0);
  return pid;
}

std::string message(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::exception& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(BagFiles, AnOutputThatIsAnInputIsRefusedNamingBoth) {
  const fs::path dir = scratch("inputs");
  write(dir / "drive.bag", "#ROSBAG V2.0\n");
  fs::create_hard_link(dir / "drive.bag", dir / "hard.bag");
  fs::create_symlink(dir / "drive.bag", dir / "link.bag");
  const std::vector<lsf::LabelledPath> inputs = {{"input bag", (dir / "drive.bag").string()}};
  for (const char* name : {"drive.bag", "hard.bag", "link.bag"}) {
    const std::string text = message([&] {
      lsf::checkOutputsAgainstInputs({{"--out-bag", (dir / name).string()}}, inputs);
    });
    EXPECT_NE(text.find("refusing to write --out-bag " + (dir / name).string()), std::string::npos)
        << text;
    EXPECT_NE(text.find("it is the input bag " + (dir / "drive.bag").string()), std::string::npos);
  }
  // The same output twice, one not written yet (compared by path).
  const std::string twice = message([&] {
    lsf::checkOutputsAgainstInputs({{"--frames-csv", (dir / "x" / ".." / "rows.csv").string()},
                                    {"--out-bag", (dir / "rows.csv").string()}},
                                   inputs);
  });
  EXPECT_NE(twice.find("are the same file"), std::string::npos) << twice;
  EXPECT_EQ(message([&] {
              lsf::checkOutputsAgainstInputs({{"--out-bag", (dir / "fused.bag").string()}}, inputs);
            }),
            "");
  EXPECT_EQ(fs::file_size(dir / "drive.bag"), 13u);  // nothing written
}

TEST(BagFiles, TemporaryNamesAreHiddenAndNeverPng) {
  const std::string tmp = lsf::tempPath("/out/1317042504.967930794.png");
  const std::string name = fs::path(tmp).filename().string();
  EXPECT_EQ(fs::path(tmp).parent_path(), "/out");
  EXPECT_EQ(name.rfind(".1317042504.967930794.png~" + std::to_string(::getpid()) + "@", 0), 0u)
      << name;
  EXPECT_EQ(name.substr(name.size() - 4), ".tmp");
  EXPECT_FALSE(lsf::isStampFile(name, ".png"));
  EXPECT_TRUE(lsf::isStampFile("1317042504.967930794.png", ".png"));
  EXPECT_FALSE(lsf::isStampFile("1317042504.96793079.png", ".png"));
  EXPECT_FALSE(lsf::isStampFile("0000000005.png", ".png"));
}

TEST(BagFiles, StaleTemporaryFilesOfDeadWritersAreRemoved) {
  const fs::path dir = scratch("stale");
  const std::string mine = fs::path(lsf::tempPath((dir / "a.png").string())).filename().string();
  const std::string host = mine.substr(mine.find('@') + 1, mine.size() - mine.find('@') - 5);
  const long dead = deadPid();
  const std::string dead_temp = ".b.png~" + std::to_string(dead) + "@" + host + ".tmp";
  const std::string other_host = ".c.png~" + std::to_string(dead) + "@elsewhere.tmp";
  const std::string older = "1.000000000.png.tmp" + std::to_string(dead) + ".png";
  for (const auto& n : {mine, dead_temp, other_host, older, std::string("1.000000000.png")}) {
    write(dir / n, "x");
  }
  EXPECT_EQ(lsf::removeStaleTemps(dir.string(), false), 2);
  EXPECT_TRUE(fs::exists(dir / mine));        // this process runs
  EXPECT_TRUE(fs::exists(dir / other_host));  // another host's: it may run
  EXPECT_FALSE(fs::exists(dir / dead_temp));
  EXPECT_FALSE(fs::exists(dir / older));
  EXPECT_TRUE(fs::exists(dir / "1.000000000.png"));
  EXPECT_EQ(lsf::removeStaleTemps(dir.string(), true), 2);  // no writer can run: every one
  EXPECT_TRUE(fs::exists(dir / "1.000000000.png"));
}

TEST(BagFiles, AFolderThatCannotBeWrittenIsNamedWithTheReason) {
  const fs::path dir = scratch("unwritable");
  write(dir / "file", "x");
  const std::string text =
      message([&] { lsf::requireWritableFolder((dir / "file").string(), "output"); });
  EXPECT_NE(text.find("cannot write in " + (dir / "file").string() + " (output): it is a file"),
            std::string::npos)
      << text;
  const std::string below =
      message([&] { lsf::requireWritableFolder((dir / "file" / "sub").string(), "output"); });
  EXPECT_NE(below.find("cannot create it: Not a directory"), std::string::npos) << below;
  EXPECT_EQ(message([&] { lsf::requireWritableFolder((dir / "new" / "sub").string(), "o"); }), "");
  EXPECT_TRUE(fs::is_directory(dir / "new" / "sub"));
  EXPECT_TRUE(fs::is_empty(dir / "new" / "sub"));  // the probe is gone
}

TEST(BagFiles, ForceRemovesOnlyTheOutputsOfARun) {
  const fs::path dir = scratch("force");
  fs::create_directories(dir / "cloud");
  for (const char* n : {"1.000000001.png", "frames.csv", "manifest.txt", "notes.txt",
                        "0000000001.png", "cloud/1.000000001.pcd"}) {
    write(dir / n, "x");
  }
  EXPECT_TRUE(lsf::holdsOutputs(dir.string()));
  EXPECT_EQ(lsf::removeEarlierOutputs(dir.string()), 4);
  EXPECT_TRUE(fs::exists(dir / "notes.txt"));
  EXPECT_TRUE(fs::exists(dir / "0000000001.png"));
  EXPECT_FALSE(lsf::holdsOutputs(dir.string()));
}

TEST(Manifest, SaysWhatDiffersAndIgnoresWhereTheBagLies) {
  const fs::path dir = scratch("manifest");
  write(dir / "a.bag", "#ROSBAG V2.0\none drive");
  write(dir / "b.bag", "#ROSBAG V2.0\nanother drive");
  lsf::FusionParams params;
  const lsf::NodeParams node;
  const lsf::Manifest a =
      lsf::runManifest("0.1.0", {(dir / "a.bag").string()}, {}, params, node, 3.0);
  EXPECT_TRUE(a.differences(lsf::Manifest::parse(a.text())).empty());
  EXPECT_EQ(a.get("param.method"), "fused_bi");
  EXPECT_EQ(a.get("param.patchmatch.num_threads"), "");  // results do not depend on it
  EXPECT_EQ(a.get("node.max_rate"), "");                 // the live node's only
  EXPECT_EQ(a.get("node.num_rings"), "64");
  params.method = lsf::Method::kLidarBI;
  const lsf::Manifest other =
      lsf::runManifest("0.1.0", {(dir / "b.bag").string()}, {}, params, node, 3.0);
  std::string differences;
  for (const auto& d : other.differences(a)) differences += d + "\n";
  EXPECT_NE(differences.find("param.method: fused_bi -> lidar_bi"), std::string::npos)
      << differences;
  EXPECT_NE(differences.find("bag1.size: 22 -> 26"), std::string::npos) << differences;
  EXPECT_NE(differences.find("bag1.hash:"), std::string::npos);
  EXPECT_EQ(differences.find("bag1.path"), std::string::npos);  // an archive may move
  // The same bag moved: nothing differs.
  fs::copy_file(dir / "a.bag", dir / "moved.bag");
  fs::last_write_time(dir / "moved.bag", fs::last_write_time(dir / "a.bag"));
  params.method = lsf::Method::kFusedBI;
  EXPECT_TRUE(lsf::runManifest("0.1.0", {(dir / "moved.bag").string()}, {}, params, node, 3.0)
                  .differences(a)
                  .empty());
}
