#include "camproj/camera.h"

#include <cmath>
#include <stdexcept>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace camproj {
namespace {

// A camera rotated 90 degrees about y and moved: x_cam = R x_world + t with R = [0 0 1; 0 1 0;
// -1 0 0], t = (0, 0, 10), so a world point's depth is z_cam = 10 - x_world whatever its y and z.
Rigid3 TurnedCamera() {
  Rigid3 cam_from_world;
  cam_from_world.rotation << 0, 0, 1, 0, 1, 0, -1, 0, 0;
  cam_from_world.translation = {0, 0, 10};
  return cam_from_world;
}

// Points whose pixel a double cannot hold have none (PixelFromWorld); without a lens, rays far
// off the axis still project (the zero lens terms overflowed to NaN before session 37).
TEST(CameraTest, PixelsBeyondADoubleAreNone) {
  Camera camera;
  camera.image_size = {1000, 800};
  camera.intrinsics.fx = camera.intrinsics.fy = 1000.0;
  camera.intrinsics.cx = 499.5;
  camera.intrinsics.cy = 399.5;
  // |x| = 1e200: r^4 overflows; the pinhole pixel is 1e203 + cx.
  const std::optional<Eigen::Vector2d> far = PixelFromWorld(camera, {1e200, 0.0, 1.0});
  ASSERT_TRUE(far.has_value());
  EXPECT_EQ(far->x(), 1000.0 * 1e200 + 499.5);
  EXPECT_EQ(far->y(), 399.5);
  EXPECT_FALSE(PixelFromWorld(camera, {1e300, 0.0, 1e-300}).has_value());  // x = inf
  camera.intrinsics.k1 = -0.1;
  EXPECT_FALSE(PixelFromWorld(camera, {1e200, 0.0, 1.0}).has_value());  // the lens overflows
  camera.projection = Projection::kOrthographic;
  camera.intrinsics.k1 = 0.0;
  EXPECT_FALSE(PixelFromWorld(camera, {1e306, 0.0, 1.0}).has_value());  // fx x = inf
  // Cam coordinates that overflow from finite ones: no pixel, for both projections (the
  // perspective one threw "point_in_cam must be finite").
  camera.cam_from_world.translation = {1e308, 0.0, 0.0};
  for (const Projection projection : {Projection::kOrthographic, Projection::kPerspective}) {
    camera.projection = projection;
    EXPECT_FALSE(PixelFromWorld(camera, {1e308, 0.0, 1.0}).has_value());
  }
}

TEST(CameraTest, DepthRangeCoveringBoxByHand) {
  // x in [1, 4]: depths 6 (the x = 4 corners) to 9 (x = 1). With the 10 % margin: near 6 / 1.1,
  // far 9 * 1.1. The first corner at depth 6 is index 1 (x from max, y and z from min).
  const BoxInWorld box{{1, -2, -3}, {4, 5, 6}};
  const DepthRangeOfBox range = DepthRangeCoveringBox(TurnedCamera(), box, 0.1);
  EXPECT_EQ(range.min_depth, 6.0);
  EXPECT_EQ(range.max_depth, 9.0);
  EXPECT_EQ(range.nearest_corner, 1);
  EXPECT_EQ(box.Corner(range.nearest_corner), Eigen::Vector3d(4, -2, -3));
  ASSERT_TRUE(range.z_near.has_value());
  EXPECT_DOUBLE_EQ(*range.z_near, 6.0 / 1.1);
  EXPECT_DOUBLE_EQ(range.z_far, 9.9);
  // Margin 0: the corners' depths themselves.
  const DepthRangeOfBox tight = DepthRangeCoveringBox(TurnedCamera(), box, 0.0);
  EXPECT_EQ(*tight.z_near, 6.0);
  EXPECT_EQ(tight.z_far, 9.0);
  // The identity camera looks down +z: a box at z in [2, 5] gives depths 2 to 5.
  const DepthRangeOfBox ahead = DepthRangeCoveringBox(Rigid3{}, BoxInWorld{{-1, -1, 2}, {1, 1, 5}}, 0.0);
  EXPECT_EQ(*ahead.z_near, 2.0);
  EXPECT_EQ(ahead.z_far, 5.0);
}

TEST(CameraTest, DepthRangeOfABoxReachingBehindTheCameraHasNoNear) {
  // x in [-1, 12]: depths -2 (x = 12, behind) to 11. No near plane covers it; far still does.
  const DepthRangeOfBox range = DepthRangeCoveringBox(TurnedCamera(), BoxInWorld{{-1, 0, 0}, {12, 1, 1}});
  EXPECT_FALSE(range.z_near.has_value());
  EXPECT_EQ(range.min_depth, -2.0);
  EXPECT_DOUBLE_EQ(range.z_far, 11.0 * 1.1);
}

TEST(CameraTest, DepthRangeRefusesABoxBehindTheCameraAndBadBoxes) {
  try {
    DepthRangeCoveringBox(TurnedCamera(), BoxInWorld{{11, 0, 0}, {12, 1, 1}});
    FAIL() << "a box wholly behind the camera was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("entirely behind the camera"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("depth -1"), std::string::npos) << e.what();
  }
  EXPECT_THROW(DepthRangeCoveringBox(Rigid3{}, BoxInWorld{{0, 0, 2}, {1, -1, 3}}), std::invalid_argument);
  EXPECT_THROW(DepthRangeCoveringBox(Rigid3{}, BoxInWorld{{0, 0, 2}, {1, 1, NAN}}), std::invalid_argument);
  EXPECT_THROW(DepthRangeCoveringBox(Rigid3{}, BoxInWorld{{0, 0, 2}, {1, 1, 3}}, -0.1),
               std::invalid_argument);
  // A NaN pose was "entirely behind the camera (depth nan)"; now the pose's own message.
  Rigid3 nan_pose;
  nan_pose.rotation(0, 0) = NAN;
  EXPECT_THAT([&] { DepthRangeCoveringBox(nan_pose, BoxInWorld{{0, 0, 2}, {1, 1, 3}}); },
              ::testing::ThrowsMessage<std::invalid_argument>(
                  ::testing::HasSubstr("rotation must be finite")));
  // Ranges beyond a double: far = inf for a margin of 1e308, near underflowing to 0, a corner
  // whose depth overflows. Each was returned as it came out.
  const auto beyond = ::testing::ThrowsMessage<std::invalid_argument>(
      ::testing::HasSubstr("cannot be represented in a double"));
  EXPECT_THAT([] { DepthRangeCoveringBox(Rigid3{}, BoxInWorld{{0, 0, 2}, {1, 1, 3}}, 1e308); },
              beyond);
  EXPECT_THAT([] { DepthRangeCoveringBox(Rigid3{}, BoxInWorld{{0, 0, 1e-320}, {1, 1, 3}}, 1e10); },
              beyond);
  Rigid3 far_pose;
  far_pose.translation = {0.0, 0.0, 1e308};
  EXPECT_THAT([&] { DepthRangeCoveringBox(far_pose, BoxInWorld{{0, 0, 0}, {1, 1, 1e308}}); },
              beyond);
}

}  // namespace
}  // namespace camproj
