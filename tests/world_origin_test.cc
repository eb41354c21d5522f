#include "camproj/world_origin.h"

#include <cmath>
#include <random>
#include <stdexcept>

#include <gtest/gtest.h>

#include "camproj/camera.h"
#include "camproj/gl.h"
#include "seeds.h"
#include "test_scenes.h"

namespace camproj {
namespace {

// A camera at `center` looking down world -z (R = diag(1, -1, -1): cam y down is world -y).
Camera CameraAt(const Eigen::Vector3d& center) {
  Camera camera;
  camera.image_size = {1920, 1080};
  camera.intrinsics.fx = 1000.0;
  camera.intrinsics.fy = 1000.0;
  camera.intrinsics.cx = 959.5;
  camera.intrinsics.cy = 539.5;
  camera.cam_from_world = CamFromWorldFromCenter(Eigen::Matrix3d(Eigen::Vector3d(1.0, -1.0, -1.0).asDiagonal()), center);
  camera.z_near = 5.0;
  camera.z_far = 500.0;
  return camera;
}

// The rule of docs/conventions.md, section 12, by hand: per axis to the nearest multiple of the
// largest power of ten not above the extent.
TEST(WorldOriginTest, RoundOriginRoundsToAPowerOfTenOfTheExtent) {
  const Eigen::Vector3d center(412345.67, 5612345.67, 123.4);
  EXPECT_EQ(RoundOrigin(center, 87.0), Eigen::Vector3d(412350.0, 5612350.0, 120.0));
  EXPECT_EQ(RoundOrigin(center, 100.0), Eigen::Vector3d(412300.0, 5612300.0, 100.0));
  EXPECT_EQ(RoundOrigin(center, 99.999), Eigen::Vector3d(412350.0, 5612350.0, 120.0));
  EXPECT_EQ(RoundOrigin(center, 1000.0), Eigen::Vector3d(412000.0, 5612000.0, 0.0));
  EXPECT_EQ(RoundOrigin(center, 0.0), Eigen::Vector3d(412346.0, 5612346.0, 123.0));
  // Below 1 the result is the double nearest the decimal users would type.
  EXPECT_EQ(RoundOrigin(Eigen::Vector3d(0.0312, -1.23456, 7.0), 0.05),
            Eigen::Vector3d(0.03, -1.23, 7.0));
  EXPECT_EQ(RoundOrigin(-center, 87.0), Eigen::Vector3d(-412350.0, -5612350.0, -120.0));
  // No negative zero (it would print as "-0").
  EXPECT_FALSE(std::signbit(RoundOrigin(Eigen::Vector3d(-1.0, 0.0, 0.0), 10.0).x()));
  EXPECT_THROW(RoundOrigin(center, -1.0), std::invalid_argument);
  EXPECT_THROW(RoundOrigin(center, NAN), std::invalid_argument);
  EXPECT_THROW(RoundOrigin(Eigen::Vector3d(NAN, 0.0, 0.0), 1.0), std::invalid_argument);
}

// Steps a double cannot scale by (10^300 overflows) or round to (2^53 steps from 0) leave the
// coordinate as it is; the origin is always finite. A valid camera at 1e10 with near 1e-300
// exported with --origin auto threw "world origin must be finite, got -inf".
TEST(WorldOriginTest, ExtremeStepsKeepTheCoordinateAndStayFinite) {
  const Eigen::Vector3d far_away(1e10, -1e10, 3.0);
  EXPECT_EQ(RoundOrigin(far_away, 1e-300), far_away);
  EXPECT_EQ(RoundOrigin(far_away, 1e-320), far_away);
  EXPECT_EQ(RoundOrigin(Eigen::Vector3d(1.7e308, 0.0, 0.0), 1e308),
            Eigen::Vector3d(1.7e308, 0.0, 0.0));
  EXPECT_EQ(RoundOrigin(Eigen::Vector3d(1e20, 0.5, 0.0), 1.0), Eigen::Vector3d(1e20, 1.0, 0.0));
  Camera camera = CameraAt(Eigen::Vector3d(1e10, 0.0, 0.0));
  camera.z_near = 1e-300;
  EXPECT_TRUE(AutoOriginOfCamera(camera).allFinite());
  EXPECT_EQ(AutoOriginOfCamera(camera), CameraCenterInWorld(camera.cam_from_world));
}

// The origin is within step * sqrt(3) / 2 of the centre (each axis within step / 2), for any
// centre and extent.
TEST(WorldOriginTest, RoundedOriginLiesWithinHalfAStepPerAxis) {
  std::mt19937_64 rng(testing::Seed(1301));
  for (int i = 0; i < 2000; ++i) {
    const Eigen::Vector3d center = testing::UniformVector3(rng, Eigen::Vector3d(-1e7, -1e7, -1e3),
                                                           Eigen::Vector3d(1e7, 1e7, 1e3));
    const double extent = testing::LogUniform(rng, 1e-3, 1e5);
    const Eigen::Vector3d origin = RoundOrigin(center, extent);
    const double step = std::pow(10.0, std::floor(std::log10(extent)));
    // step / 2 plus the rounding of the centre's quotient (|center| * 2^-52, <= 2.3e-9 here).
    const double tolerance = 0.5 * step * (1.0 + 1e-9) + 1e-8;
    for (int axis = 0; axis < 3; ++axis) {
      EXPECT_LE(std::abs(origin[axis] - center[axis]), tolerance) << "extent " << extent;
    }
  }
}

TEST(WorldOriginTest, AutoOriginOfPointsIsTheirRoundedCentroid) {
  // Centroid (412345, 5612345.5, 120.25); bounding box 40 x 1 x 0.5: step 10.
  const std::vector<Eigen::Vector3d> points = {{412325.0, 5612345.0, 120.0},
                                               {412365.0, 5612346.0, 120.5}};
  EXPECT_EQ(AutoOriginOfPoints(points), Eigen::Vector3d(412350.0, 5612350.0, 120.0));
  EXPECT_EQ(AutoOriginOfPoints({{1.5, 2.5, -3.5}}), Eigen::Vector3d(2.0, 3.0, -4.0));  // extent 0
  EXPECT_THROW(AutoOriginOfPoints({}), std::invalid_argument);
  EXPECT_THROW(AutoOriginOfPoints({{0.0, INFINITY, 0.0}}), std::invalid_argument);
}

// At export time only the camera is known: its centre rounded to a power of ten not above near,
// so the origin is nearer to the camera than any point the frustum draws.
TEST(WorldOriginTest, AutoOriginOfCameraIsItsCentreRoundedByNear) {
  Camera camera = CameraAt({412345.67, 5612345.67, 123.4});
  EXPECT_EQ(AutoOriginOfCamera(camera), Eigen::Vector3d(412346.0, 5612346.0, 123.0));
  camera.z_near = 0.25;
  EXPECT_EQ(AutoOriginOfCamera(camera), Eigen::Vector3d(412345.7, 5612345.7, 123.4));
}

// Hand-computed: R = diag(1, -1, -1), C = (100, 200, 300), O = (100, 200, 0): the view matrix
// for X - O is [diag(1,1,1) | (0, 0, -300)] as gl_eye = diag(1,-1,-1) cam and cam = R (X - C).
TEST(WorldOriginTest, ViewMatrixRelativeToTheOriginByHand) {
  const Camera camera = CameraAt({100.0, 200.0, 300.0});
  const Eigen::Matrix4d view = GlEyeFromOriginWorld(camera.cam_from_world, {100.0, 200.0, 0.0});
  Eigen::Matrix4d expected = Eigen::Matrix4d::Identity();
  expected(2, 3) = -300.0;
  EXPECT_EQ(view, expected);
  EXPECT_THROW(GlEyeFromOriginWorld(camera.cam_from_world, {NAN, 0.0, 0.0}), std::invalid_argument);
}

// The purpose of the matrix: gl_eye_from_origin_world (X - O) = gl_eye_from_world X for any pose
// and origin. In double the two sides differ by rounding of numbers of size |X| + |t| (a few
// products and sums, each within 2^-53 of its size): 16 eps (|X| + |t|) covers them.
TEST(WorldOriginTest, ViewMatrixRelativeToTheOriginSeesTheSamePoints) {
  std::mt19937_64 rng(testing::Seed(1302));
  for (int i = 0; i < 500; ++i) {
    const testing::RandomCamera random = testing::MakeRandomCamera(rng);
    const Eigen::Vector3d offset = testing::UniformVector3(rng, Eigen::Vector3d(-1e7, -1e7, -1e4),
                                                           Eigen::Vector3d(1e7, 1e7, 1e4));
    // The camera and its scene moved to survey coordinates.
    const Rigid3 cam_from_world = random.cam_from_world * Rigid3{Eigen::Matrix3d::Identity(), -offset};
    const Eigen::Vector3d origin = RoundOrigin(offset, 10.0);
    const Eigen::Matrix4d absolute = GlEyeFromWorld(cam_from_world);
    const Eigen::Matrix4d relative = GlEyeFromOriginWorld(cam_from_world, origin);
    EXPECT_EQ(Eigen::Matrix3d(relative.topLeftCorner<3, 3>()), Eigen::Matrix3d(absolute.topLeftCorner<3, 3>()));
    const Eigen::Vector3d point = offset + testing::UniformVector3(rng, -5, 5);
    const Eigen::Vector4d from_absolute = absolute * point.homogeneous();
    const Eigen::Vector4d from_relative = relative * (point - origin).homogeneous();
    const double tolerance =
        16.0 * 2.220446049250313e-16 * (point.norm() + cam_from_world.translation.norm());
    EXPECT_LE((from_absolute - from_relative).norm(), tolerance);
  }
}

// Float32PixelError's formula by hand (world_origin.h): 3 u f (|C - O| + Z) / Z.
TEST(WorldOriginTest, Float32ErrorByHand) {
  Camera camera = CameraAt({0.0, 0.0, 5.0e6});
  camera.intrinsics.fy = 1100.0;
  camera.intrinsics.skew = 50.0;  // f = 1100 + 50
  const double u = 5.9604644775390625e-08;
  EXPECT_DOUBLE_EQ(Float32PixelError(camera, std::nullopt, 10.0), 3.0 * u * 1150.0 * (5.0e6 + 10.0) / 10.0);
  EXPECT_DOUBLE_EQ(Float32PixelError(camera, Eigen::Vector3d(0.0, 0.0, 5.0e6 - 3.0), 10.0),
                   3.0 * u * 1150.0 * 13.0 / 10.0);
  // ~34 px for raw coordinates at 5e6, 2.7e-4 px relative to a nearby origin: the 0.1 px warning
  // level lies between them.
  EXPECT_GT(Float32PixelError(camera, std::nullopt, 10.0), 100.0 * kFloat32ErrorWarningPx);
  EXPECT_LT(Float32PixelError(camera, Eigen::Vector3d(0.0, 0.0, 5.0e6), 10.0), 1e-3);
  camera.projection = Projection::kOrthographic;
  EXPECT_DOUBLE_EQ(Float32PixelError(camera, std::nullopt, 10.0), 3.0 * u * 1150.0 * (5.0e6 + 10.0));
  EXPECT_THROW(Float32PixelError(camera, std::nullopt, 0.0), std::invalid_argument);
  EXPECT_THROW(Float32PixelError(camera, Eigen::Vector3d(NAN, 0.0, 0.0), 1.0), std::invalid_argument);
}

// The origin is part of the camera's GL views only: the view matrix for world coordinates, the
// pixels and the pose are unchanged; a non-finite origin is an invalid camera.
TEST(WorldOriginTest, CameraViewsCarryTheOriginRelativeViewMatrix) {
  Camera camera = CameraAt({412345.67, 5612345.67, 123.4});
  const CameraViews plain = ViewsOfCamera(camera);
  EXPECT_EQ(plain.gl_eye_from_origin_world, plain.gl_eye_from_world);
  camera.world_origin = Eigen::Vector3d(412350.0, 5612350.0, 120.0);
  const CameraViews views = ViewsOfCamera(camera);
  EXPECT_EQ(views.gl_eye_from_world, plain.gl_eye_from_world);
  EXPECT_EQ(views.gl_eye_from_origin_world,
            GlEyeFromOriginWorld(camera.cam_from_world, *camera.world_origin));
  camera.world_origin = Eigen::Vector3d(0.0, NAN, 0.0);
  EXPECT_THROW(camera.Check(), std::invalid_argument);
}

}  // namespace
}  // namespace camproj
