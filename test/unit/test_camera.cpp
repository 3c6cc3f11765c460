// Copyright wild_mvs authors.
#include <gtest/gtest.h>

#include "wild_mvs/core/camera.h"
#include "wild_mvs/core/error.h"

namespace wild_mvs {
namespace {

Camera MakeCamera() {
  Camera c;
  c.fx = 500;
  c.fy = 510;
  c.cx = 320;
  c.cy = 240;
  c.width = 640;
  c.height = 480;
  c.R = Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized())
            .toRotationMatrix();
  c.t = Eigen::Vector3d(0.1, -0.2, 2.0);
  return c;
}

TEST(Camera, ProjectBackprojectRoundTrip) {
  const Camera c = MakeCamera();
  const Eigen::Vector2d px(100.25, 400.75);
  const Eigen::Vector3d X = c.Backproject(px, 3.5);
  EXPECT_NEAR(c.Depth(X), 3.5, 1e-12);
  Eigen::Vector2d back;
  ASSERT_TRUE(c.Project(X, &back));
  EXPECT_NEAR((back - px).norm(), 0, 1e-9);
  // The world ray through px passes through X.
  const Eigen::Vector3d ray = c.RayWorld(px);
  EXPECT_NEAR(ray.norm(), 1, 1e-12);
  EXPECT_NEAR((c.Center() + ray * (X - c.Center()).norm() - X).norm(), 0, 1e-9);
}

TEST(Camera, BehindCameraDoesNotProject) {
  const Camera c = MakeCamera();
  Eigen::Vector2d px;
  EXPECT_FALSE(c.Project(c.Backproject({10, 10}, -1.0), &px));
}

TEST(Camera, PixelCentreConventionSurvivesResize) {
  // The image's top-left corner (0,0) and bottom-right corner (w,h) map to the
  // same rays after halving the resolution.
  const Camera c = MakeCamera();
  const Camera h = c.Resized(320, 240);
  EXPECT_NEAR((c.RayCam({0, 0}) - h.RayCam({0, 0})).norm(), 0, 1e-12);
  EXPECT_NEAR((c.RayCam({640, 480}) - h.RayCam({320, 240})).norm(), 0, 1e-12);
  // The centre of full-res pixel block (0..1, 0..1) is half-res (0.5,0.5)/2.
  EXPECT_NEAR((c.RayCam({1, 1}) - h.RayCam({0.5, 0.5})).norm(), 0, 1e-12);
}

TEST(Camera, ValidateRejectsBadCameras) {
  Camera c = MakeCamera();
  EXPECT_NO_THROW(c.Validate("cam"));
  Camera bad = c;
  bad.fx = 0;
  EXPECT_THROW(bad.Validate("cam"), Error);
  bad = c;
  bad.fy = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(bad.Validate("cam"), Error);
  bad = c;
  bad.R(0, 0) += 0.1;
  EXPECT_THROW(bad.Validate("cam"), Error);
  bad = c;
  bad.R = -c.R;  // reflection
  EXPECT_THROW(bad.Validate("cam"), Error);
  try {
    bad.Validate("images.txt line 7");
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("images.txt line 7"),
              std::string::npos);
  }
}

TEST(Camera, NearestRotationIsOrthonormal) {
  Eigen::Matrix3d R = MakeCamera().R;
  R(0, 1) += 1e-4;
  const Eigen::Matrix3d Q = NearestRotation(R);
  EXPECT_NEAR((Q * Q.transpose() - Eigen::Matrix3d::Identity()).norm(), 0,
              1e-12);
  EXPECT_NEAR(Q.determinant(), 1, 1e-12);
}

}  // namespace
}  // namespace wild_mvs
