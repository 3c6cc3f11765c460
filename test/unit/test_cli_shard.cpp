// Copyright wild_mvs authors. `wild_mvs reconstruct --shard K/N`: three
// shards run concurrently as separate processes into one OUT, then
// `wild_mvs fuse OUT`, give the same depth maps (bit for bit) and the same
// fused cloud as one `wild_mvs reconstruct`, on a rendered dataset without
// sparse points (so the shared tracks of `--stages sparse` are tested too).
// Also: the split itself, bad --shard values, a shard without the tracks,
// shards with options other than OUT/run.yaml's.
#include <gtest/gtest.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "synthetic_scene.h"
#include "test_paths.h"
#include "wild_mvs/cli/args.h"
#include "wild_mvs/cli/scene_setup.h"
#include "wild_mvs/io/ply.h"

extern char** environ;

namespace wild_mvs {
namespace {

namespace fs = std::filesystem;

std::string ReadFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// Starts `wild_mvs ARGS > log 2>&1` as a child process; returns its pid.
pid_t Spawn(const std::string& args, const std::string& log) {
  const std::string cmd = std::string("exec '") + WILD_MVS_CLI + "' " + args +
                          " >'" + log + "' 2>&1";
  const char* argv[] = {"/bin/sh", "-c", cmd.c_str(), nullptr};
  pid_t pid = -1;
  if (posix_spawn(&pid, "/bin/sh", nullptr, nullptr,
                  const_cast<char* const*>(argv), environ) != 0) {
    return -1;
  }
  return pid;
}

int Wait(pid_t pid) {
  int st = 0;
  if (pid < 0 || waitpid(pid, &st, 0) != pid) return -1;
  return WIFEXITED(st) ? WEXITSTATUS(st) : 128 + WTERMSIG(st);
}

struct RunResult {
  int status = -1;
  std::string output;
};

RunResult RunCli(const std::string& args, const std::string& log) {
  RunResult r;
  r.status = Wait(Spawn(args, log));
  r.output = ReadFile(log);
  return r;
}

// Relative paths of the regular files under dir/sub.
std::set<std::string> FilesUnder(const std::string& dir,
                                 const std::string& sub) {
  std::set<std::string> files;
  if (!fs::is_directory(dir + "/" + sub)) return files;
  for (const auto& e : fs::recursive_directory_iterator(dir + "/" + sub)) {
    if (e.is_regular_file()) {
      files.insert(fs::relative(e.path(), dir).string());
    }
  }
  return files;
}

int CountTempFiles(const std::string& dir) {
  int n = 0;
  for (const auto& e : fs::recursive_directory_iterator(dir)) {
    if (e.path().filename().string().find(".tmp") != std::string::npos) ++n;
  }
  return n;
}

// Map files (under `subs`) and fused clouds of two OUT folders: the same
// files, byte for byte, and the same points.
void ExpectSameResults(const std::string& a_dir, const std::string& b_dir,
                       const std::vector<std::string>& subs) {
  for (const std::string& sub : subs) {
    const std::set<std::string> a = FilesUnder(a_dir, sub),
                                b = FilesUnder(b_dir, sub);
    EXPECT_EQ(a, b) << sub;
    EXPECT_FALSE(a.empty()) << sub;
    for (const std::string& f : a) {
      EXPECT_TRUE(ReadFile(a_dir + "/" + f) == ReadFile(b_dir + "/" + f))
          << f << " differs";
    }
  }
  EXPECT_EQ(FilesUnder(a_dir, "depth").size(), 5u);
  const PointCloud a = ReadPlyCloud(a_dir + "/fused.ply");
  const PointCloud b = ReadPlyCloud(b_dir + "/fused.ply");
  ASSERT_GT(a.size(), 1000u);
  ASSERT_EQ(a.size(), b.size());
  size_t differ = 0;
  for (size_t i = 0; i < a.size(); ++i) {
    differ += (a.xyz[i] != b.xyz[i] || a.normal[i] != b.normal[i]);
  }
  EXPECT_EQ(differ, 0u);
  EXPECT_EQ(CountTempFiles(b_dir), 0);
}

const char kStages[] = " --stages depth,fuse";

class CliShard : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    testing::SyntheticSpec spec = testing::SlantedPlaneSpec(25, 5);
    spec.width = 128;
    spec.height = 96;
    spec.focal = 120;
    spec.num_sparse_points = 0;  // the tracks are computed
    const testing::SyntheticScene scene = testing::Render(spec);
    for (const View& v : scene.scene.views) stems_.push_back(v.Stem());
    root_ = testing::MakeTempDir("wild_mvs_cli_shard");
    dataset_ = root_ + "/dataset";
    testing::WriteDataset(scene, dataset_);
    single_ = root_ + "/single";
    sharded_ = root_ + "/sharded";
    const std::string common = kStages;
    single_run_ = RunCli(
        "reconstruct '" + dataset_ + "' '" + single_ + "' --threads 2" + common,
        root_ + "/single.log");
    sparse_run_ = RunCli("reconstruct '" + dataset_ + "' '" + sharded_ +
                             "' --threads 1 --stages sparse",
                         root_ + "/sparse.log");
    // The three shards at once, as separate processes.
    std::vector<pid_t> pids;
    for (int k = 1; k <= 3; ++k) {
      pids.push_back(Spawn("reconstruct '" + dataset_ + "' '" + sharded_ +
                               "' --threads 1 --shard " + std::to_string(k) +
                               "/3" + common,
                           root_ + "/shard" + std::to_string(k) + ".log"));
    }
    for (int k = 1; k <= 3; ++k) {
      RunResult r;
      r.status = Wait(pids[k - 1]);
      r.output = ReadFile(root_ + "/shard" + std::to_string(k) + ".log");
      shard_runs_.push_back(r);
    }
    fuse_run_ =
        RunCli("fuse '" + sharded_ + "' --threads 2", root_ + "/fuse.log");
  }
  static void TearDownTestSuite() {
    std::error_code ec;
    fs::remove_all(root_, ec);
  }
  static std::vector<std::string> stems_;
  static std::string root_, dataset_, single_, sharded_;
  static RunResult single_run_, sparse_run_, fuse_run_;
  static std::vector<RunResult> shard_runs_;
};
std::vector<std::string> CliShard::stems_;
std::string CliShard::root_, CliShard::dataset_, CliShard::single_,
    CliShard::sharded_;
RunResult CliShard::single_run_, CliShard::sparse_run_, CliShard::fuse_run_;
std::vector<RunResult> CliShard::shard_runs_;

TEST_F(CliShard, ConcurrentShardsThenFuseEqualOneProcess) {
  ASSERT_EQ(single_run_.status, 0) << single_run_.output;
  ASSERT_EQ(sparse_run_.status, 0) << sparse_run_.output;
  ASSERT_EQ(shard_runs_.size(), 3u);
  int views = 0;
  for (int k = 0; k < 3; ++k) {
    const RunResult& r = shard_runs_[k];
    ASSERT_EQ(r.status, 0) << r.output;
    // 5 views round robin: 2, 2, 1.
    const int expect = k < 2 ? 2 : 1;
    EXPECT_NE(r.output.find(Msg("shard ", k + 1, "/3: ", expect, " of 5")),
              std::string::npos)
        << r.output;
    views += expect;
    // The tracks of --stages sparse are read, not recomputed.
    EXPECT_NE(r.output.find("points read from"), std::string::npos) << r.output;
    EXPECT_EQ(r.output.find("computing tracks"), std::string::npos) << r.output;
    // What to run next.
    EXPECT_NE(r.output.find("wild_mvs fuse " + sharded_), std::string::npos)
        << r.output;
    EXPECT_TRUE(
        fs::exists(Msg(sharded_, "/summary_shard_", k + 1, "_of_3.json")));
  }
  EXPECT_EQ(views, 5);
  // The shards stop at the raw maps (the filter needs the neighbours').
  for (const std::string& s : stems_) {
    EXPECT_TRUE(fs::exists(sharded_ + "/raw/depth/" + s + ".pfm")) << s;
  }
  ASSERT_EQ(fuse_run_.status, 0) << fuse_run_.output;
  EXPECT_NE(fuse_run_.output.find("filtered 5 depth maps"), std::string::npos)
      << fuse_run_.output;

  // The sparse tracks: the same points.
  const std::string tracks = ReadFile(single_ + "/sparse/tracks.txt");
  EXPECT_NE(tracks.find("\npoint "), std::string::npos)
      << "no sparse points computed: the tracks file is not exercised";
  EXPECT_EQ(tracks, ReadFile(sharded_ + "/sparse/tracks.txt"));

  // Same set of map files, byte for byte (raw and final), same cloud.
  ExpectSameResults(single_, sharded_,
                    {"depth", "normal", "confidence", "cameras", "raw/depth",
                     "raw/normal", "raw/confidence"});
}

TEST_F(CliShard, WithoutTheConsistencyFilterShardsWriteFinalMaps) {
  ASSERT_EQ(single_run_.status, 0) << single_run_.output;
  // Without the consistency filter: shards write final maps; 2 at once.
  const std::string nf = std::string(kStages) + " --ablation.consistency false";
  const RunResult single_nf = RunCli("reconstruct '" + dataset_ + "' '" +
                                         root_ + "/single_nf' --threads 2" + nf,
                                     root_ + "/single_nf.log");
  const std::string sharded_nf = root_ + "/sharded_nf";
  RunCli("reconstruct '" + dataset_ + "' '" + sharded_nf +
             "' --threads 1 --stages sparse",
         root_ + "/sparse_nf.log");
  const pid_t p1 = Spawn("reconstruct '" + dataset_ + "' '" + sharded_nf +
                             "' --threads 1 --shard 1/2" + nf,
                         root_ + "/shard_nf1.log");
  const pid_t p2 = Spawn("reconstruct '" + dataset_ + "' '" + sharded_nf +
                             "' --threads 1 --shard 2/2" + nf,
                         root_ + "/shard_nf2.log");
  const bool shards_nf_ok = Wait(p1) == 0 && Wait(p2) == 0;
  const RunResult fuse_nf =
      RunCli("fuse '" + sharded_nf + "' --threads 2", root_ + "/fuse_nf.log");

  ASSERT_EQ(single_nf.status, 0) << single_nf.output;
  ASSERT_TRUE(shards_nf_ok) << ReadFile(root_ + "/shard_nf1.log")
                            << ReadFile(root_ + "/shard_nf2.log");
  ASSERT_EQ(fuse_nf.status, 0) << fuse_nf.output;
  EXPECT_FALSE(fs::exists(root_ + "/sharded_nf/raw"));
  EXPECT_EQ(fuse_nf.output.find("filtered"), std::string::npos)
      << fuse_nf.output;
  ExpectSameResults(root_ + "/single_nf", root_ + "/sharded_nf",
                    {"depth", "normal", "confidence", "cameras"});
  // The filter changes the maps: the comparison above is not vacuous.
  EXPECT_FALSE(ReadFile(single_ + "/depth/" + stems_[1] + ".pfm") ==
               ReadFile(root_ + "/single_nf/depth/" + stems_[1] + ".pfm"));
}

TEST_F(CliShard, ShardWithoutTracksOrWithOtherOptionsFailsClearly) {
  ASSERT_EQ(single_run_.status, 0) << single_run_.output;
  // No tracks in a fresh OUT: the shard asks for --stages sparse.
  const RunResult fresh = RunCli("reconstruct '" + dataset_ + "' '" + root_ +
                                     "/fresh' --threads 1 --shard 1/2",
                                 root_ + "/fresh.log");
  EXPECT_EQ(fresh.status, 1) << fresh.output;
  EXPECT_NE(fresh.output.find("--stages sparse"), std::string::npos)
      << fresh.output;
  EXPECT_FALSE(fs::exists(root_ + "/fresh/depth"));
  // Other depth options than OUT/run.yaml's (the shards of sharded_).
  ASSERT_EQ(sparse_run_.status, 0) << sparse_run_.output;
  const RunResult other =
      RunCli("reconstruct '" + dataset_ + "' '" + sharded_ +
                 "' --threads 1 --shard 2/3 --mvs.mpgc.drop_ncc 0.5",
             root_ + "/other.log");
  EXPECT_EQ(other.status, 1) << other.output;
  EXPECT_NE(other.output.find("mvs.mpgc.drop_ncc"), std::string::npos)
      << other.output;
  EXPECT_NE(other.output.find("every shard"), std::string::npos)
      << other.output;
}

TEST(CliShardArgs, BadShardValuesAreUsageErrors) {
  const std::string root = testing::MakeTempDir("wild_mvs_cli_shard_args");
  for (const char* bad_c :
       {"0/3", "4/3", "x", "3", "1/0", "a/3", "1/3/4", "/3"}) {
    const std::string bad = bad_c;
    const RunResult r = RunCli(
        "reconstruct /nonexistent '" + root + "/out' --shard '" + bad + "'",
        root + "/log");
    EXPECT_EQ(r.status, 2) << bad << ": " << r.output;
    EXPECT_NE(r.output.find("--shard '" + bad + "'"), std::string::npos)
        << bad << ": " << r.output;
    EXPECT_NE(r.output.find("K/N"), std::string::npos) << r.output;
  }
  std::error_code ec;
  fs::remove_all(root, ec);
}

TEST(ShardViews, SharesAreDisjointCompleteAndRoundRobin) {
  const std::vector<int> views = {7, 2, 9, 0, 4, 5, 1};  // any order
  std::vector<int> all;
  for (int k = 1; k <= 3; ++k) {
    const std::vector<int> s = cli::ShardViews(views, cli::Shard{k, 3});
    all.insert(all.end(), s.begin(), s.end());
    EXPECT_EQ(s, cli::ShardViews({0, 1, 2, 4, 5, 7, 9}, cli::Shard{k, 3}));
  }
  // Sorted order 0 1 2 4 5 7 9: shard 1 = 0 4 9, 2 = 1 5, 3 = 2 7.
  EXPECT_EQ(cli::ShardViews(views, cli::Shard{1, 3}),
            (std::vector<int>{0, 4, 9}));
  EXPECT_EQ(cli::ShardViews(views, cli::Shard{3, 3}), (std::vector<int>{2, 7}));
  std::sort(all.begin(), all.end());
  EXPECT_EQ(all, (std::vector<int>{0, 1, 2, 4, 5, 7, 9}));
  // More shards than views: the last ones are empty.
  EXPECT_TRUE(cli::ShardViews({3}, cli::Shard{2, 2}).empty());
  const cli::Shard s = cli::ParseShard("2/8");
  EXPECT_EQ(s.index, 2);
  EXPECT_EQ(s.count, 8);
  EXPECT_THROW(cli::ParseShard("9/8"), cli::UsageError);
}

}  // namespace
}  // namespace wild_mvs
