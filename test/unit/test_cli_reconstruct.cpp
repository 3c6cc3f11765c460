// Copyright wild_mvs authors. End-to-end tests of `wild_mvs reconstruct`
// (the built binary) on a small rendered dataset with exact ground truth:
// valid and accurate files, resumability, --force, thread-count
// independence, atomic outputs, clear errors for bad output folders, views
// and masks, and a run killed with SIGKILL and resumed.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "synthetic_scene.h"
#include "test_paths.h"
#include "wild_mvs/core/metrics.h"
#include "wild_mvs/io/depth_map_io.h"
#include "wild_mvs/io/pfm.h"

namespace wild_mvs {
namespace {

namespace fs = std::filesystem;

struct RunResult {
  int status = -1;
  std::string output;  // stdout + stderr
};

RunResult RunCli(const std::string& args) {
  RunResult r;
  const std::string cmd =
      std::string("'") + WILD_MVS_CLI + "' " + args + " 2>&1";
  FILE* p = popen(cmd.c_str(), "r");
  if (!p) return r;
  char buf[4096];
  size_t n;
  while ((n = fread(buf, 1, sizeof(buf), p)) > 0) r.output.append(buf, n);
  const int st = pclose(p);
  r.status = WIFEXITED(st) ? WEXITSTATUS(st) : 128 + WTERMSIG(st);
  return r;
}

std::string ReadFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

int CountTempFiles(const std::string& dir) {
  int n = 0;
  for (const auto& e : fs::recursive_directory_iterator(dir)) {
    if (e.path().filename().string().find(".tmp") != std::string::npos) ++n;
  }
  return n;
}

int Count(const std::string& text, const std::string& what) {
  int n = 0;
  for (size_t p = text.find(what); p != std::string::npos;
       p = text.find(what, p + 1)) {
    ++n;
  }
  return n;
}

class CliReconstruct : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    testing::SyntheticSpec spec = testing::SlantedPlaneSpec(25, 4);
    spec.width = 128;
    spec.height = 96;
    spec.focal = 120;
    spec.num_sparse_points = 200;
    scene_ = new testing::SyntheticScene(testing::Render(spec));
    root_ = testing::MakeTempDir("wild_mvs_cli_reconstruct");
    dataset_ = root_ + "/dataset";
    testing::WriteDataset(*scene_, dataset_);
    out_ = root_ + "/out";
    // All stages; a coarse Poisson depth keeps the test fast.
    first_ = RunCli("reconstruct '" + dataset_ + "' '" + out_ +
                    "' --threads 2 --meshing.depth 7");
  }
  static void TearDownTestSuite() {
    delete scene_;
    std::error_code ec;
    fs::remove_all(root_, ec);
  }
  static testing::SyntheticScene* scene_;
  static std::string root_, dataset_, out_;
  static RunResult first_;
};
testing::SyntheticScene* CliReconstruct::scene_ = nullptr;
std::string CliReconstruct::root_, CliReconstruct::dataset_,
    CliReconstruct::out_;
RunResult CliReconstruct::first_;

TEST_F(CliReconstruct, WritesAccurateDepthMapsForEveryView) {
  ASSERT_EQ(first_.status, 0) << first_.output;
  EXPECT_NE(first_.output.find("summary: 4 views (4 computed, 0 resumed)"),
            std::string::npos)
      << first_.output;
  EXPECT_EQ(CountTempFiles(out_), 0);
  EXPECT_TRUE(fs::exists(out_ + "/run.yaml"));
  EXPECT_TRUE(fs::exists(out_ + "/fused.ply"));
  EXPECT_TRUE(fs::exists(out_ + "/mesh.ply"));
  EXPECT_TRUE(fs::exists(out_ + "/summary.json"));
  for (size_t i = 0; i < scene_->scene.views.size(); ++i) {
    const View& v = scene_->scene.views[i];
    const std::string s = v.Stem();
    for (const std::string& f :
         {"/depth/" + s + ".pfm", "/normal/" + s + ".pfm",
          "/confidence/" + s + ".pfm", "/cameras/" + s + ".txt",
          "/log/" + s + ".json", "/preview/" + s + "_depth.png"}) {
      EXPECT_TRUE(fs::exists(out_ + f)) << f;
    }
    const DepthMapFiles files = ReadDepthMapFiles(out_, s);
    const DepthMap& m = files.map;
    ASSERT_FALSE(m.empty());
    // The depth map's camera is the view's pose.
    EXPECT_LT((m.camera.Center() - v.camera.Center()).norm(), 1e-6);
    const DepthMetrics dm =
        EvaluateDepth(m.depth, m.camera, scene_->depth[i], v.camera);
    SCOPED_TRACE(s + ": " + dm.ToString());
    // A textured plane seen by 4 views: most of it is reconstructed and
    // accurate.
    EXPECT_GT(dm.completeness, 0.5);
    EXPECT_LT(dm.median_rel_error, 0.005);
    ASSERT_FALSE(dm.relative_accuracy.empty());
    EXPECT_GT(dm.relative_accuracy[0], 0.9);  // within 1 %
    const std::string log = ReadFile(out_ + "/log/" + s + ".json");
    EXPECT_NE(log.find("\"view\": \"" + v.name + "\""), std::string::npos);
    EXPECT_NE(log.find("\"samples\": " + std::to_string(m.CountValid())),
              std::string::npos)
        << log;
  }
}

TEST_F(CliReconstruct, SecondRunResumesAndForceRecomputes) {
  ASSERT_EQ(first_.status, 0) << first_.output;
  const std::string s0 = scene_->scene.views[0].Stem();
  const auto t0 = fs::last_write_time(out_ + "/depth/" + s0 + ".pfm");
  const std::string depth0 = ReadFile(out_ + "/depth/" + s0 + ".pfm");
  const auto fused_time = fs::last_write_time(out_ + "/fused.ply");
  const RunResult again = RunCli("reconstruct '" + dataset_ + "' '" + out_ +
                                 "' --threads 2 --meshing.depth 7");
  ASSERT_EQ(again.status, 0) << again.output;
  EXPECT_EQ(Count(again.output, "done earlier, skipped"), 4) << again.output;
  EXPECT_NE(again.output.find("fused.ply is up to date, skipped"),
            std::string::npos)
      << again.output;
  EXPECT_NE(again.output.find("mesh.ply is up to date, skipped"),
            std::string::npos);
  EXPECT_EQ(fs::last_write_time(out_ + "/fused.ply"), fused_time);
  EXPECT_NE(again.output.find("(0 computed, 4 resumed)"), std::string::npos);
  EXPECT_EQ(fs::last_write_time(out_ + "/depth/" + s0 + ".pfm"), t0);

  // A view whose files are incomplete (log missing) is recomputed.
  const std::string s1 = scene_->scene.views[1].Stem();
  fs::remove(out_ + "/log/" + s1 + ".json");
  const RunResult partial = RunCli("reconstruct '" + dataset_ + "' '" + out_ +
                                   "' --threads 2 --stages depth");
  ASSERT_EQ(partial.status, 0) << partial.output;
  EXPECT_NE(partial.output.find("(1 computed, 3 resumed)"), std::string::npos)
      << partial.output;

  // --force on one view recomputes it, with the same result.
  const RunResult forced =
      RunCli("reconstruct '" + dataset_ + "' '" + out_ +
             "' --threads 2 --stages depth --force --views " + s0);
  ASSERT_EQ(forced.status, 0) << forced.output;
  EXPECT_NE(forced.output.find("(1 computed, 0 resumed)"), std::string::npos)
      << forced.output;
  EXPECT_EQ(ReadFile(out_ + "/depth/" + s0 + ".pfm"), depth0);
  EXPECT_EQ(CountTempFiles(out_), 0);
}

TEST_F(CliReconstruct, EvalScoresDepthMapsAndCloudAgainstGroundTruth) {
  ASSERT_EQ(first_.status, 0) << first_.output;
  // Depth maps against the dataset's gt_depth/ (found via --dataset, or
  // given with --gt-dir): same numbers either way.
  const RunResult a = RunCli("eval depth --est '" + out_ + "' --dataset '" +
                             dataset_ + "' --json '" + root_ + "/d.json'");
  ASSERT_EQ(a.status, 0) << a.output;
  const RunResult b = RunCli("eval depth --est '" + out_ + "' --gt-dir '" +
                             dataset_ + "/gt_depth'");
  ASSERT_EQ(b.status, 0) << b.output;
  const std::string tail_a = a.output.substr(a.output.find("all 4 views"));
  EXPECT_EQ(tail_a, b.output.substr(b.output.find("all 4 views")));
  const std::string json = ReadFile(root_ + "/d.json");
  const size_t c = json.find("\"completeness\": ");
  ASSERT_NE(c, std::string::npos) << json;
  EXPECT_GT(std::stod(json.substr(c + 16)), 0.5) << json;

  // The fused cloud against a ground-truth cloud made from the GT depth.
  const std::string gt = root_ + "/gt.ply";
  const RunResult g = RunCli("eval make-gt-cloud --dataset '" + dataset_ +
                             "' --stride 2 '" + gt + "'");
  ASSERT_EQ(g.status, 0) << g.output;
  // tau = 1 % of the scene size.
  const double tau = 0.01 * scene_->scene_size;
  const RunResult e =
      RunCli("eval cloud '" + out_ + "/fused.ply' '" + gt + "' --tau " +
             std::to_string(tau) + " --json '" + root_ + "/c.json'");
  ASSERT_EQ(e.status, 0) << e.output;
  const std::string cj = ReadFile(root_ + "/c.json");
  const size_t f = cj.find("\"fscore\": [");
  ASSERT_NE(f, std::string::npos) << cj;
  EXPECT_GT(std::stod(cj.substr(f + 11)), 0.5) << e.output;
  // The mesh's vertices can be scored too.
  const RunResult m = RunCli("eval cloud '" + out_ + "/mesh.ply' '" + gt +
                             "' --tau " + std::to_string(tau));
  EXPECT_EQ(m.status, 0) << m.output;

  // Usage errors.
  RunResult u = RunCli("eval depth --est '" + out_ + "'");
  EXPECT_EQ(u.status, 1) << u.output;
  EXPECT_NE(u.output.find("needs --gt-dir"), std::string::npos);
  u = RunCli("eval cloud '" + gt + "' '" + gt + "' --tau 0,1");
  EXPECT_EQ(u.status, 2) << u.output;
  EXPECT_NE(u.output.find("--tau: 0 must be > 0"), std::string::npos);
  u = RunCli("eval cloud '" + root_ + "/missing.ply' '" + gt + "'");
  EXPECT_EQ(u.status, 1) << u.output;
  EXPECT_NE(u.output.find("missing.ply"), std::string::npos);
  u = RunCli("eval bogus");
  EXPECT_EQ(u.status, 2) << u.output;
}

TEST_F(CliReconstruct, FuseAndMeshCommandsWorkOnTheFolder) {
  ASSERT_EQ(first_.status, 0) << first_.output;
  const RunResult f =
      RunCli("fuse '" + out_ + "' --output '" + root_ + "/refused.ply'");
  ASSERT_EQ(f.status, 0) << f.output;
  // The same cloud as the reconstruct run (same options from run.yaml).
  EXPECT_EQ(ReadFile(root_ + "/refused.ply"), ReadFile(out_ + "/fused.ply"));
  const RunResult m = RunCli(
      "mesh '" + out_ + "' --meshing.depth 6 --output '" + root_ + "/m6.ply'");
  ASSERT_EQ(m.status, 0) << m.output;
  EXPECT_TRUE(fs::exists(root_ + "/m6.ply"));
  const RunResult bad = RunCli("fuse '" + root_ + "/nothing_here'");
  EXPECT_EQ(bad.status, 1);
  EXPECT_NE(bad.output.find("nothing_here: not a folder"), std::string::npos)
      << bad.output;
}

TEST_F(CliReconstruct, OutputDoesNotDependOnThreadCount) {
  ASSERT_EQ(first_.status, 0) << first_.output;
  const std::string s = scene_->scene.views[2].Stem();
  const std::string out1 = root_ + "/out_one_thread";
  const RunResult r = RunCli("reconstruct '" + dataset_ + "' '" + out1 +
                             "' --threads 1 --stages depth");
  ASSERT_EQ(r.status, 0) << r.output;
  // The matched maps (raw/) and the consistency-filtered ones.
  for (const std::string& dir : {std::string("/raw"), std::string()}) {
    for (const std::string& f :
         {"/depth/" + s + ".pfm", "/normal/" + s + ".pfm",
          "/confidence/" + s + ".pfm", "/cameras/" + s + ".txt"}) {
      ASSERT_TRUE(fs::exists(out_ + dir + f)) << dir + f;
      EXPECT_EQ(ReadFile(out1 + dir + f), ReadFile(out_ + dir + f)) << dir + f;
    }
  }
}

TEST_F(CliReconstruct, BadOutputFolderViewsAndMasksGiveClearErrors) {
  // OUT below a regular file: cannot be created.
  const std::string file = root_ + "/a_file";
  std::ofstream(file) << "x";
  RunResult r = RunCli("reconstruct '" + dataset_ + "' '" + file + "/out'");
  EXPECT_EQ(r.status, 1) << r.output;
  EXPECT_NE(r.output.find("wild_mvs reconstruct: " + file + "/out"),
            std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("cannot create the output folder"),
            std::string::npos);

  // OUT exists but its depth/ is a file: the write fails, named, and
  // nothing else is damaged.
  const std::string out2 = root_ + "/out_blocked";
  fs::create_directories(out2);
  std::ofstream(out2 + "/depth") << "not a folder";
  r = RunCli("reconstruct '" + dataset_ + "' '" + out2 +
             "' --stages depth --threads 2 --views " +
             scene_->scene.views[0].Stem());
  EXPECT_EQ(r.status, 1) << r.output;
  EXPECT_NE(r.output.find("wild_mvs reconstruct: "), std::string::npos);
  EXPECT_NE(r.output.find(out2 + "/depth"), std::string::npos) << r.output;
  EXPECT_EQ(ReadFile(out2 + "/depth"), "not a folder");
  EXPECT_EQ(CountTempFiles(out2), 0);

  // Unknown view.
  r = RunCli("reconstruct '" + dataset_ + "' '" + root_ +
             "/out_v' --views nonexistent_view");
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("--views: no view named 'nonexistent_view'"),
            std::string::npos)
      << r.output;

  // Missing dataset.
  r = RunCli("reconstruct '" + root_ + "/no_such_dataset' '" + root_ +
             "/out_d'");
  EXPECT_EQ(r.status, 1) << r.output;
  EXPECT_NE(r.output.find("no_such_dataset"), std::string::npos) << r.output;

  // A mask of the wrong size names the mask file; the run fails for that
  // view only, and says so.
  const std::string masks = root_ + "/masks";
  fs::create_directories(masks);
  const View& v0 = scene_->scene.views[0];
  cv::imwrite(masks + "/" + v0.Stem() + ".png",
              cv::Mat(7, 9, CV_8U, cv::Scalar(255)));
  r = RunCli("reconstruct '" + dataset_ + "' '" + root_ +
             "/out_m' --stages depth --threads 2 --mask-dir '" + masks +
             "' --views " + v0.Stem());
  EXPECT_EQ(r.status, 1) << r.output;
  EXPECT_NE(r.output.find(masks + "/" + v0.Stem() + ".png: mask is 9x7"),
            std::string::npos)
      << r.output;
}

TEST_F(CliReconstruct, UnreadableOutputFolderAndEarlierResults) {
  // OUT is a regular file: refused, named, and the file is untouched.
  const std::string file = root_ + "/out_is_a_file";
  std::ofstream(file) << "keep me";
  RunResult r = RunCli("reconstruct '" + dataset_ + "' '" + file + "'");
  EXPECT_EQ(r.status, 1) << r.output;
  EXPECT_NE(r.output.find("wild_mvs reconstruct: " + file), std::string::npos)
      << r.output;
  EXPECT_EQ(ReadFile(file), "keep me");

  // An earlier depth map that cannot be read (truncated PFM) when a later
  // stage needs it: the error names the file, the run exits 1, no fused
  // cloud or temporary file is written and the other results are untouched.
  ASSERT_EQ(first_.status, 0) << first_.output;
  const std::string out = root_ + "/out_unreadable";
  fs::copy(out_, out, fs::copy_options::recursive);
  fs::remove(out + "/fused.ply");
  fs::remove(out + "/mesh.ply");
  const std::string stem0 = scene_->scene.views[0].Stem();
  const std::string stem1 = scene_->scene.views[1].Stem();
  const DepthMapPaths bad = MakeDepthMapPaths(out, stem0);
  const std::string good = MakeDepthMapPaths(out, stem1).depth;
  const std::string good_before = ReadFile(good);
  {
    const std::string head = ReadFile(bad.depth).substr(0, 20);
    std::ofstream(bad.depth, std::ios::binary | std::ios::trunc) << head;
  }
  r = RunCli("reconstruct '" + dataset_ + "' '" + out +
             "' --stages fuse --threads 2");
  EXPECT_EQ(r.status, 1) << r.output;
  EXPECT_NE(r.output.find(bad.depth), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("truncated"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(out + "/fused.ply"));
  EXPECT_EQ(CountTempFiles(out), 0);
  EXPECT_EQ(ReadFile(good), good_before);
}

TEST_F(CliReconstruct, MaskExcludesPixels) {
  // The left half of view 0 masked out: no depth there, depth elsewhere.
  const View& v0 = scene_->scene.views[0];
  const std::string masks = root_ + "/half_masks";
  fs::create_directories(masks);
  cv::Mat m(v0.camera.height, v0.camera.width, CV_8U, cv::Scalar(255));
  m.colRange(0, m.cols / 2).setTo(0);
  cv::imwrite(masks + "/" + v0.name + ".png", m);
  const std::string out = root_ + "/out_masked";
  const RunResult r = RunCli("reconstruct '" + dataset_ + "' '" + out +
                             "' --stages depth --threads 2 --mask-dir '" +
                             masks + "' --views " + v0.Stem());
  ASSERT_EQ(r.status, 0) << r.output;
  const DepthMap d = ReadDepthMapFiles(out, v0.Stem()).map;
  ASSERT_EQ(d.width(), v0.camera.width);  // no rescaling on this scene
  const int half = d.width() / 2;
  EXPECT_EQ(cv::countNonZero(d.depth.colRange(0, half)), 0);
  EXPECT_GT(cv::countNonZero(d.depth.colRange(half, d.width())),
            d.height() * half / 3);
}

// The files of OUT (relative paths) that are results: every regular file but
// the atomic writer's temporary files (".NAME.tmp...") and the run's own
// timing records (summary.json).
std::vector<std::string> ResultFiles(const std::string& dir) {
  std::vector<std::string> files;
  for (const auto& e : fs::recursive_directory_iterator(dir)) {
    if (!e.is_regular_file()) continue;
    const std::string name = e.path().filename().string();
    if (name.find(".tmp") != std::string::npos || name == "summary.json")
      continue;
    files.push_back(fs::relative(e.path(), dir).string());
  }
  std::sort(files.begin(), files.end());
  return files;
}

int CountFiles(const std::string& dir, const std::string& ext) {
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) return 0;
  int n = 0;
  for (const auto& e : fs::directory_iterator(dir)) {
    const std::string name = e.path().filename().string();
    n += e.is_regular_file() && name[0] != '.' && name.size() > ext.size() &&
         name.compare(name.size() - ext.size(), ext.size(), ext) == 0;
  }
  return n;
}

TEST(CliReconstructKill, ResumesAfterSigkillWithTheUninterruptedResult) {
  // 8 views of a textured plane; a run killed (SIGKILL: no clean-up) once
  // at least one view is done, then run again, ends with the same files and
  // the same bytes as a run that was never interrupted.
  testing::SyntheticSpec spec = testing::SlantedPlaneSpec(25, 8);
  spec.width = 128;
  spec.height = 96;
  spec.focal = 120;
  spec.num_sparse_points = 300;
  const testing::SyntheticScene scene = testing::Render(spec);
  const std::string root = testing::MakeTempDir("wild_mvs_cli_kill");
  const std::string dataset = root + "/dataset";
  testing::WriteDataset(scene, dataset);
  const std::string args = " --threads 2 --stages depth,fuse";
  const std::string whole = root + "/whole", killed = root + "/killed";
  const RunResult ref =
      RunCli("reconstruct '" + dataset + "' '" + whole + "'" + args);
  ASSERT_EQ(ref.status, 0) << ref.output;

  // Started directly (fork + exec) so that its pid is known.
  const pid_t pid = fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    const std::string log = root + "/killed.log";
    const int fd = open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (fd >= 0) {
      dup2(fd, 1);
      dup2(fd, 2);
    }
    execl(WILD_MVS_CLI, WILD_MVS_CLI, "reconstruct", dataset.c_str(),
          killed.c_str(), "--threads", "2", "--stages", "depth,fuse",
          static_cast<char*>(nullptr));
    _exit(127);
  }
  // Killed as soon as a view's log exists (raw maps first: the consistency
  // filter is on), i.e. in the middle of the depth stage.
  bool done_one = false, exited = false;
  int status = 0;
  const auto t0 = std::chrono::steady_clock::now();
  while (!done_one &&
         std::chrono::steady_clock::now() - t0 < std::chrono::seconds(300)) {
    done_one = CountFiles(killed + "/raw/log", ".json") +
                   CountFiles(killed + "/log", ".json") >=
               1;
    if (waitpid(pid, &status, WNOHANG) == pid) {
      exited = true;
      break;
    }
    if (!done_one) usleep(2000);  // polling the condition
  }
  if (!exited) {
    kill(pid, SIGKILL);
    ASSERT_EQ(waitpid(pid, &status, 0), pid);
  }
  ASSERT_TRUE(done_one) << "no view finished within 300 s";
  ASSERT_FALSE(exited && WIFEXITED(status))
      << "the run ended before it could be killed; "
         "the test needs a longer run";
  ASSERT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL);
  const int raw_done = CountFiles(killed + "/raw/log", ".json");
  EXPECT_LT(raw_done, 8) << "killed after the depth stage: not a mid-run kill";
  EXPECT_FALSE(fs::exists(killed + "/fused.ply"));
  std::printf("killed after %d of 8 views, %d temporary files left\n", raw_done,
              CountTempFiles(killed));

  // The rerun resumes the finished views and completes the rest.
  const RunResult again =
      RunCli("reconstruct '" + dataset + "' '" + killed + "'" + args);
  ASSERT_EQ(again.status, 0) << again.output;
  EXPECT_GE(Count(again.output, "matched earlier, to be filtered"), raw_done)
      << again.output;
  EXPECT_NE(again.output.find("summary: 8 views"), std::string::npos);

  // Same set of results, byte for byte (depth, normal, confidence maps,
  // cameras, previews, logs but their timings, the fused cloud); temporary
  // files a kill leaves behind are never taken as results.
  const std::vector<std::string> want = ResultFiles(whole);
  ASSERT_EQ(ResultFiles(killed), want);
  int compared_maps = 0;
  for (const std::string& f : want) {
    if (f.rfind("log/", 0) == 0 || f.rfind("raw/log/", 0) == 0 ||
        f == "run.yaml")
      continue;  // timings and the dataset path differ
    EXPECT_EQ(ReadFile(killed + "/" + f), ReadFile(whole + "/" + f)) << f;
    compared_maps += f.rfind("depth/", 0) == 0;
  }
  EXPECT_EQ(compared_maps, 8);
  for (const View& v : scene.scene.views) {
    const std::string log = ReadFile(killed + "/log/" + v.Stem() + ".json");
    const DepthMap m = ReadDepthMapFiles(killed, v.Stem()).map;
    EXPECT_NE(log.find("\"samples\": " + std::to_string(m.CountValid())),
              std::string::npos)
        << v.Stem();
  }
  std::error_code ec;
  fs::remove_all(root, ec);
}

}  // namespace
}  // namespace wild_mvs
