// Copyright wild_mvs authors. Bundler, Middlebury, Strecha and projection
// matrix readers: exact conversions on synthetic cameras, and malformed
// files (error names file, line and problem).
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <sstream>

#include "test_paths.h"
#include "wild_mvs/core/error.h"
#include "wild_mvs/io/bundler.h"
#include "wild_mvs/io/dataset.h"
#include "wild_mvs/io/middlebury.h"
#include "wild_mvs/io/projmatrix.h"
#include "wild_mvs/io/strecha.h"

namespace wild_mvs {
namespace {

namespace fs = std::filesystem;

void WriteImage(const std::string& path, int w, int h) {
  fs::create_directories(fs::path(path).parent_path());
  ASSERT_TRUE(cv::imwrite(path, cv::Mat(h, w, CV_8UC3, cv::Scalar(9, 8, 7))));
}
void WriteText(const std::string& path, const std::string& s) {
  fs::create_directories(fs::path(path).parent_path());
  std::ofstream(path, std::ios::binary) << s;
}
std::string ReplaceLine(const std::string& text, int line,
                        const std::string& content) {
  std::istringstream in(text);
  std::string l, out;
  for (int n = 1; std::getline(in, l); ++n)
    out += (n == line ? content : l) + "\n";
  return out;
}
template <typename F>
void ExpectError(F f, const std::vector<std::string>& parts) {
  try {
    f();
    ADD_FAILURE() << "no error (expected '" << parts.back() << "')";
  } catch (const Error& e) {
    for (const std::string& p : parts)
      EXPECT_NE(std::string(e.what()).find(p), std::string::npos)
          << "'" << e.what() << "' lacks '" << p << "'";
  }
}

// Ground-truth cameras in our convention.
Camera TrueCamera(int i, int w, int h, double f) {
  Camera c;
  c.width = w;
  c.height = h;
  c.fx = c.fy = f;
  c.cx = 0.5 * w;
  c.cy = 0.5 * h;
  c.R = (Eigen::AngleAxisd(0.15 * i, Eigen::Vector3d::UnitY()) *
         Eigen::AngleAxisd(0.05, Eigen::Vector3d::UnitX()))
            .toRotationMatrix();
  c.t = Eigen::Vector3d(0.2 * i, -0.1, 3.0);
  return c;
}

// ---------------------------------------------------------------- Bundler
struct BundlerFixture {
  std::string dir;
  std::vector<Camera> cams;  // truth, camera 1 unregistered (f = 0)
  std::vector<Eigen::Vector3d> points;
  double k1 = -0.08, k2 = 0.01;
  std::string bundle, list;
};

BundlerFixture MakeBundler() {
  BundlerFixture b;
  b.dir = testing::MakeTempDir("bundler");
  const int w = 80, h = 60;
  for (int i = 0; i < 3; ++i) b.cams.push_back(TrueCamera(i, w, h, 70 + i));
  for (int p = 0; p < 20; ++p)
    b.points.emplace_back(0.05 * (p % 5) - 0.1, 0.04 * (p / 5) - 0.08,
                          0.01 * p);
  std::ostringstream os, ls;
  os.precision(17);
  os << "# Bundle file v0.3\n" << 3 << " " << b.points.size() << "\n";
  const Eigen::Matrix3d flip = Eigen::Vector3d(1, -1, -1).asDiagonal();
  for (int i = 0; i < 3; ++i) {
    const Camera& c = b.cams[i];
    os << (i == 1 ? 0.0 : c.fx) << " " << b.k1 << " " << b.k2 << "\n";
    const Eigen::Matrix3d Rb = flip * c.R;
    const Eigen::Vector3d tb = flip * c.t;
    for (int r = 0; r < 3; ++r)
      os << Rb(r, 0) << " " << Rb(r, 1) << " " << Rb(r, 2) << "\n";
    os << tb.x() << " " << tb.y() << " " << tb.z() << "\n";
    const std::string img = "images/v" + std::to_string(i) + ".jpg";
    ls << img << " 0 " << c.fx << "\n";
    if (i != 1) WriteImage(b.dir + "/" + img, w, h);
  }
  for (size_t p = 0; p < b.points.size(); ++p) {
    os << b.points[p].x() << " " << b.points[p].y() << " " << b.points[p].z()
       << "\n10 20 30\n";
    // Point 0 is seen by camera 1 only (dropped); others by all three.
    std::vector<int> seen =
        p == 0 ? std::vector<int>{1} : std::vector<int>{0, 1, 2};
    os << seen.size();
    for (int i : seen) {
      const Camera& c = b.cams[i];
      const Eigen::Vector3d P = flip * (c.R * b.points[p] + c.t);  // Bundler
      const Eigen::Vector2d pn = -P.head<2>() / P.z();
      const double r2 = pn.squaredNorm();
      const Eigen::Vector2d pd = c.fx * (1 + b.k1 * r2 + b.k2 * r2 * r2) * pn;
      os << " " << i << " " << p << " " << pd.x() << " " << pd.y();
    }
    os << "\n";
  }
  b.bundle = os.str();
  b.list = ls.str();
  WriteText(b.dir + "/bundle/bundle.out", b.bundle);
  WriteText(b.dir + "/list.txt", b.list);
  return b;
}

TEST(Bundler, ConvertsFrameDistortionAndSkipsUnregistered) {
  const BundlerFixture b = MakeBundler();
  DatasetOptions o;
  o.path = b.dir;
  const Scene s = LoadDataset(o);
  ASSERT_EQ(s.views.size(), 2u);
  EXPECT_EQ(s.views[0].name, "images/v0.jpg");
  EXPECT_EQ(s.views[1].name, "images/v2.jpg");
  EXPECT_NE(s.source.find("images/v1.jpg"), std::string::npos) << s.source;
  const Camera* truth[2] = {&b.cams[0], &b.cams[2]};
  for (int v = 0; v < 2; ++v) {
    const Camera& c = s.views[v].camera;
    EXPECT_EQ(c.width, 80);
    EXPECT_EQ(c.height, 60);
    EXPECT_DOUBLE_EQ(c.cx, 40);
    EXPECT_DOUBLE_EQ(c.cy, 30);
    EXPECT_DOUBLE_EQ(c.fx, truth[v]->fx);
    EXPECT_LT((c.R - truth[v]->R).norm(), 1e-12);
    EXPECT_LT((c.t - truth[v]->t).norm(), 1e-12);
    EXPECT_EQ(s.views[v].distortion.model, Distortion::Model::kRadial);
    EXPECT_DOUBLE_EQ(s.views[v].distortion.k1, b.k1);
    EXPECT_DOUBLE_EQ(s.views[v].distortion.k2, b.k2);
  }
  ASSERT_EQ(s.points.size(), b.points.size() - 1);  // point 0 dropped
  for (size_t p = 0; p < s.points.size(); ++p) {
    ASSERT_EQ(s.points[p].track.size(), 2u);
    for (const Observation& o : s.points[p].track) {
      Eigen::Vector2d px;
      ASSERT_TRUE(s.views[o.view].camera.Project(s.points[p].xyz, &px));
      EXPECT_LT((px - o.xy).norm(), 1e-6) << "point " << p;
    }
  }
  fs::remove_all(b.dir);
}

TEST(Bundler, MalformedInputs) {
  const BundlerFixture b = MakeBundler();
  const std::string bo = b.dir + "/bundle/bundle.out";
  const std::string lt = b.dir + "/list.txt";
  auto read = [&] { ReadBundler(bo, lt); };
  // Line numbers: 1 comment, 2 header, camera i at 3 + 5 i.
  const std::vector<
      std::pair<std::pair<int, std::string>, std::vector<std::string>>>
      cases = {
          {{2, "3"}, {"bundle.out line 2", "header"}},
          {{2, "4 20"}, {"bundle.out line 2", "lists 3 images"}},
          {{2, "0 0"}, {"bundle.out line 2", "empty model"}},
          {{3, "70 -0.08"}, {"bundle.out line 3", "truncated"}},
          {{3, "nan -0.08 0.01"}, {"bundle.out line 3", "not a finite"}},
          {{3, "-70 -0.08 0.01"}, {"bundle.out line 3", "focal length"}},
          {{4, "2 0 0"}, {"bundle.out lines 4-6", "not orthonormal"}},
          {{6, "0 0"}, {"bundle.out line 6", "truncated"}},
          {{21, "1 2 3 4"}, {"bundle.out line 21", "3 values"}},
          {{22, "10 20 300"}, {"bundle.out line 22", "outside 0..255"}},
          {{23, "1 7 0 1 2"}, {"bundle.out line 23", "camera 7"}},
          {{23, "2 0 0 1 2"}, {"bundle.out line 23", "truncated"}},
      };
  for (const auto& [edit, expect] : cases) {
    SCOPED_TRACE(edit.second);
    WriteText(bo, ReplaceLine(b.bundle, edit.first, edit.second));
    ExpectError(read, expect);
  }
  // Truncated file (points missing).
  WriteText(bo, b.bundle.substr(0, b.bundle.size() / 2));
  ExpectError(read, {"bundle.out", "truncated"});
  // Image missing on disk.
  WriteText(bo, b.bundle);
  fs::remove(b.dir + "/images/v2.jpg");
  ExpectError(read, {"v2.jpg", "missing"});
  fs::remove_all(b.dir);
}

// ---------------------------------------------------------------- Middlebury
std::string ParLine(const std::string& name, const Camera& c) {
  std::ostringstream os;
  os.precision(17);
  os << name << " " << c.fx << " 0 " << c.cx - 0.5 << " 0 " << c.fy << " "
     << c.cy - 0.5 << " 0 0 1";
  for (int r = 0; r < 3; ++r)
    for (int k = 0; k < 3; ++k) os << " " << c.R(r, k);
  os << " " << c.t.x() << " " << c.t.y() << " " << c.t.z();
  return os.str();
}

TEST(Middlebury, ReadsAndRejectsMalformed) {
  const std::string d = testing::MakeTempDir("mb");
  std::string par = "3\n";
  std::vector<Camera> cams;
  for (int i = 0; i < 3; ++i) {
    Camera c = TrueCamera(i, 64, 48, 100 + i);
    c.cx = 31.2;
    c.cy = 25.7;
    cams.push_back(c);
    const std::string name = "s" + std::to_string(i) + ".png";
    par += ParLine(name, c) + "\n";
    WriteImage(d + "/" + name, 64, 48);
  }
  WriteText(d + "/x_par.txt", par);
  DatasetOptions o;
  o.path = d;
  const Scene s = LoadDataset(o);
  ASSERT_EQ(s.views.size(), 3u);
  for (int i = 0; i < 3; ++i) {
    const Camera& c = s.views[i].camera;
    EXPECT_NEAR(c.cx, 31.2, 1e-12);
    EXPECT_NEAR(c.cy, 25.7, 1e-12);
    EXPECT_EQ(c.width, 64);
    EXPECT_LT((c.P() - cams[i].P()).norm(), 1e-9);
  }
  const std::string pf = d + "/x_par.txt";
  auto read = [&] { ReadMiddleburyPar(pf); };
  Camera bad = cams[1];
  bad.fx = 0;
  const std::string l2 = ParLine("s1.png", cams[1]);
  const std::vector<
      std::pair<std::pair<int, std::string>, std::vector<std::string>>>
      cases = {
          {{1, "x"}, {"x_par.txt line 1", "not an integer"}},
          {{1, "0"}, {"x_par.txt line 1", "empty model"}},
          {{1, "4"}, {"x_par.txt line 5", "truncated"}},
          {{3, l2.substr(0, l2.rfind(' '))}, {"x_par.txt line 3", "truncated"}},
          {{3, ParLine("s1.png", bad)}, {"x_par.txt line 3", "focal length"}},
          {{3, "s1.png 100 0 30 0 100 20 0 0 1 1 0 0 0 1 0 0 0 1 inf 0 0"},
           {"x_par.txt line 3", "not a finite"}},
          {{3, "s1.png 100 0 30 0 100 20 0 0 1 1 0 0 0 1 0.2 0 0 1 0 0 0"},
           {"x_par.txt line 3", "not orthonormal"}},
          {{3, "s1.png 100 5 30 0 100 20 0 0 1 1 0 0 0 1 0 0 0 1 0 0 0"},
           {"x_par.txt line 3", "skew"}},
          {{3, ParLine("s0.png", cams[1])},
           {"x_par.txt line 3", "duplicate image name 's0.png'"}},
          {{3, ParLine("nothere.png", cams[1])}, {"nothere.png", "missing"}},
      };
  for (const auto& [edit, expect] : cases) {
    SCOPED_TRACE(edit.second);
    WriteText(pf, ReplaceLine(par, edit.first, edit.second));
    ExpectError(read, expect);
  }
  fs::remove_all(d);
}

// ---------------------------------------------------------------- Strecha
std::string StrechaFile(const Camera& c) {
  std::ostringstream os;
  os.precision(17);
  os << c.fx << " 0 " << c.cx - 0.5 << "\n0 " << c.fy << " " << c.cy - 0.5
     << "\n0 0 1\n0 0 0\n";
  const Eigen::Matrix3d Rc2w = c.R.transpose();
  for (int r = 0; r < 3; ++r)
    os << Rc2w(r, 0) << " " << Rc2w(r, 1) << " " << Rc2w(r, 2) << "\n";
  const Eigen::Vector3d C = c.Center();
  os << C.x() << " " << C.y() << " " << C.z() << "\n"
     << c.width << " " << c.height << "\n";
  return os.str();
}

TEST(Strecha, ReadsAndRejectsMalformed) {
  const std::string d = testing::MakeTempDir("strecha");
  std::vector<Camera> cams;
  for (int i = 0; i < 2; ++i) {
    Camera c = TrueCamera(i, 60, 40, 90);
    c.cx = 29.3;
    c.cy = 21.1;
    cams.push_back(c);
    WriteText(d + "/cameras/000" + std::to_string(i) + ".jpg.camera",
              StrechaFile(c));
    WriteImage(d + "/images/000" + std::to_string(i) + ".jpg", 60, 40);
  }
  DatasetOptions o;
  o.path = d;
  Scene s = LoadDataset(o);
  ASSERT_EQ(s.views.size(), 2u);
  EXPECT_EQ(s.views[1].name, "0001.jpg");
  for (int i = 0; i < 2; ++i)
    EXPECT_LT((s.views[i].camera.P() - cams[i].P()).norm(), 1e-9);
  // Image of the wrong size on disk.
  WriteImage(d + "/images/0001.jpg", 61, 40);
  ExpectError([&] { LoadDataset(o); }, {"0001.jpg", "61x40", "60x40"});
  fs::remove(d + "/images/0001.jpg");
  ExpectError([&] { LoadDataset(o); }, {"0001.jpg", "missing"});

  const std::string cf = d + "/cameras/0000.jpg.camera";
  const std::string good = StrechaFile(cams[0]);
  auto read = [&] { ReadStrechaCamera(cf); };
  const std::vector<
      std::pair<std::pair<int, std::string>, std::vector<std::string>>>
      cases = {
          {{1, "-90 0 29"}, {"0000.jpg.camera", "focal length"}},
          {{2, "0 nan 20"}, {"0000.jpg.camera line 2", "not a finite"}},
          {{2, "0 90"}, {"0000.jpg.camera line 2", "truncated"}},
          {{4, "0.1 0 0"}, {"0000.jpg.camera line 4", "distortion"}},
          {{5, "1 1 0"}, {"0000.jpg.camera lines 5-7", "not orthonormal"}},
          {{9, "60"}, {"0000.jpg.camera line 9", "truncated"}},
          {{9, "0 40"}, {"0000.jpg.camera line 9", "image size"}},
      };
  for (const auto& [edit, expect] : cases) {
    SCOPED_TRACE(edit.second);
    WriteText(cf, ReplaceLine(good, edit.first, edit.second));
    ExpectError(read, expect);
  }
  WriteText(cf, good.substr(0, good.size() / 2));
  ExpectError(read, {"0000.jpg.camera", "truncated"});
  fs::remove_all(d);
}

// ------------------------------------------------------ projection matrices
TEST(ProjMatrix, DecompositionRecoversKRt) {
  Camera c = TrueCamera(2, 640, 360, 500);
  c.fy = 510;
  c.cx = 320.7;
  c.cy = 170.2;
  // P in integer-centre pixels, arbitrary (negative) scale.
  Eigen::Matrix3d K0 = c.K();
  K0(0, 2) -= 0.5;
  K0(1, 2) -= 0.5;
  Eigen::Matrix<double, 3, 4> Rt;
  Rt << c.R, c.t;
  const Eigen::Matrix<double, 3, 4> P = -3.7 * K0 * Rt;
  const Camera d = DecomposeProjectionMatrix(P, "test");
  EXPECT_NEAR(d.fx, 500, 1e-9);
  EXPECT_NEAR(d.fy, 510, 1e-9);
  EXPECT_NEAR(d.cx, 320.7, 1e-9);
  EXPECT_NEAR(d.cy, 170.2, 1e-9);
  EXPECT_LT((d.R - c.R).norm(), 1e-12);
  EXPECT_LT((d.t - c.t).norm(), 1e-12);
  Eigen::Matrix<double, 3, 4> degenerate = P;
  degenerate.col(1) = degenerate.col(0);
  ExpectError([&] { DecomposeProjectionMatrix(degenerate, "f.projmatrix"); },
              {"f.projmatrix", "degenerate"});
  const std::string d2 = testing::MakeTempDir("projm");
  WriteText(d2 + "/cameras/003.projmatrix", "1 2 3 4\n5 6 7 8\n");
  ExpectError([&] { ReadProjectionMatrix(d2 + "/cameras/003.projmatrix"); },
              {"003.projmatrix line 3", "truncated"});
  WriteText(d2 + "/cameras/003.projmatrix", "1 2 3 4\n5 6 7 8\n1 2 nan 4\n");
  ExpectError([&] { ReadProjectionMatrix(d2 + "/cameras/003.projmatrix"); },
              {"003.projmatrix line 3", "not a finite"});
  fs::remove_all(d2);
}

}  // namespace
}  // namespace wild_mvs
