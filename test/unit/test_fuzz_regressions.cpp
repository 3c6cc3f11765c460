// Copyright wild_mvs authors. Inputs that the fuzz harnesses (test/fuzz/)
// found to crash, hang or misbehave, fed again to the fixed code. Each input
// is also kept in the harness's seed corpus (test/fuzz/corpus/<harness>/).
// In the sanitizer build (scripts/run_sanitizers.sh) these tests catch the
// memory errors themselves; in the normal build they check the results.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "test_paths.h"
#include "wild_mvs/cli/option_set.h"
#include "wild_mvs/cli/reconstruct_config.h"
#include "wild_mvs/core/error.h"
#include "wild_mvs/io/image_size.h"
#include "wild_mvs/io/ply.h"
#include "wild_mvs/io/sparse_tracks_file.h"

namespace wild_mvs {
namespace {

std::string ReadCorpus(const std::string& harness, const std::string& name) {
  const std::string path =
      testing::SourceDir() + "/test/fuzz/corpus/" + harness + "/" + name;
  std::ifstream f(path, std::ios::binary);
  EXPECT_TRUE(f.good()) << path;
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

// fuzz_yaml_config, first run: OptionSet::LoadYamlString kept references to
// the key / value nodes of a yaml-cpp iterator proxy that dies at the end of
// the statement (AddressSanitizer: stack-use-after-scope in
// YAML::Node::Mark()) on every config file. Fixed by copying the nodes.
TEST(FuzzRegressions, YamlConfigKeysOutliveTheIterator) {
  cli::ReconstructConfig config;
  cli::OptionSet options;
  cli::RegisterOptions(&config, &options);
  options.LoadYamlString(ReadCorpus("yaml_config", "small"), "small.yaml");
  EXPECT_EQ(config.run.threads, 2);
  EXPECT_EQ(config.image.max_image_size, 640);
  EXPECT_DOUBLE_EQ(config.image.cache_mb, 256.5);
  // The default config (the tool's own --dump-config) loads too.
  cli::ReconstructConfig defaults;
  cli::OptionSet options2;
  cli::RegisterOptions(&defaults, &options2);
  options2.LoadYamlString(ReadCorpus("yaml_config", "reconstruct_default"),
                          "reconstruct.yaml");
  EXPECT_TRUE(defaults.mvs.ablation.linearize);
  // Errors still name the line of the bad key.
  try {
    options.LoadYamlString("run:\n  threads: 1\n  bogus: 2\n", "bad.yaml");
    ADD_FAILURE() << "unknown key accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("bad.yaml line 3"), std::string::npos)
        << e.what();
  }
}

// fuzz_image_size, CI run: a BMP header with height INT32_MIN (a top-down
// bitmap of 2^31 rows) made ReadImageSize negate INT32_MIN (UBSan: "negation
// of -2147483648 cannot be represented in type 'int32_t'"). Fixed: such a
// height is no size, OpenCV decides, and refuses it. A normal top-down BMP
// (negative height) still gives its positive height.
TEST(FuzzRegressions, BmpHeightInt32MinIsRefused) {
  const std::string dir = testing::MakeTempDir("fuzz_bmp");
  const std::string path = dir + "/image.bmp";
  {
    std::ofstream f(path, std::ios::binary);
    f << ReadCorpus("image_size", "crash_bmp_height_int32_min");
  }
  try {
    const ImageSize s = ReadImageSize(path);
    ADD_FAILURE() << "accepted as " << s.width << "x" << s.height;
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
  }
  {
    std::ofstream f(path, std::ios::binary);
    f << ReadCorpus("image_size", "bmp_top_down");
  }
  const ImageSize s = ReadImageSize(path);
  EXPECT_EQ(s.width, 2);
  EXPECT_EQ(s.height, 2);
  std::filesystem::remove_all(dir);
}

// fuzz_ply, found by a CI fuzz run: an ASCII face list entry of
// 2.2e11 was cast to int before its range check (UBSan: float-cast-overflow
// in ply.cpp). Now the file is refused, naming it and the face.
TEST(FuzzRegressions, PlyFaceIndexOverIntMaxIsRefused) {
  const std::string dir = ::testing::TempDir() + "/wild_mvs_fuzz_ply";
  std::filesystem::create_directories(dir);
  const std::string path = dir + "/face.ply";
  {
    std::ofstream f(path, std::ios::binary);
    f << ReadCorpus("ply", "crash_face_index_over_int_max");
  }
  for (int mesh = 0; mesh < 2; ++mesh) {
    try {
      if (mesh)
        ReadPlyMesh(path);
      else
        ReadPlyCloud(path);
      ADD_FAILURE() << "accepted";
    } catch (const Error& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find(path), std::string::npos) << what;
      // The mesh reader stops earlier, at a face of 0 vertices.
      if (!mesh) {
        EXPECT_NE(what.find("refers to vertex"), std::string::npos) << what;
      }
    }
  }
  std::filesystem::remove_all(dir);
}

// fuzz_sparse_tracks: a point colour of 1e57 was read (as a double, then
// cast to float: inf) and written back as "inf", which the reader refuses:
// the round trip threw. Fixed by refusing a colour beyond float's range.
TEST(FuzzRegressions, SparseTrackColourOverFloatMaxIsRefused) {
  const std::string dir = ::testing::TempDir() + "/wild_mvs_fuzz_tracks";
  std::filesystem::create_directories(dir);
  const std::string path = dir + "/tracks.txt";
  {
    std::ofstream f(path, std::ios::binary);
    f << ReadCorpus("sparse_tracks", "crash_colour_over_float_max");
  }
  Scene scene;  // the harness's scene
  for (const char* name : {"a.png", "b c.jpg"}) {
    View v;
    v.name = name;
    v.camera.width = 64;
    v.camera.height = 48;
    scene.views.push_back(v);
  }
  std::vector<SparsePoint> points;
  std::string why;
  try {
    ReadSparseTracks(path, scene,
                     {"image.max_image_size 0", "dataset.mask_dir "}, &points,
                     &why);
    ADD_FAILURE() << "accepted";
  } catch (const Error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(path), std::string::npos) << what;
    EXPECT_NE(what.find("colour out of range"), std::string::npos) << what;
  }
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace wild_mvs
