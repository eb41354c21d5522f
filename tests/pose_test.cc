#include "camproj/pose.h"

#include <limits>
#include <random>
#include <stdexcept>

#include <gtest/gtest.h>

#include "seeds.h"
#include "test_scenes.h"

namespace camproj {
namespace {

using testing::kExactRelative;

TEST(PoseTest, InverseComposesToIdentityAndCentreMapsToOrigin) {
  std::mt19937_64 rng(testing::Seed(7));
  for (int i = 0; i < 100; ++i) {
    const Eigen::Vector3d center = testing::UniformVector3(rng, -5, 5);
    const Rigid3 cam_from_world = CamFromWorldFromCenter(testing::RandomRotation(rng), center);
    EXPECT_LT((CameraCenterInWorld(cam_from_world) - center).norm(), kExactRelative * 10);
    EXPECT_LT((cam_from_world * center).norm(), kExactRelative * 10);
    const Rigid3 identity = Inverse(cam_from_world) * cam_from_world;
    EXPECT_LT((identity.rotation - Eigen::Matrix3d::Identity()).norm(), kExactRelative);
    EXPECT_LT(identity.translation.norm(), kExactRelative * 10);
    const Rigid3 round_trip = Rigid3FromMatrix(cam_from_world.ToMatrix());
    EXPECT_EQ(round_trip.rotation, cam_from_world.rotation);
    EXPECT_EQ(round_trip.translation, cam_from_world.translation);
  }
}

TEST(PoseTest, CheckRefusesReflectionsNonRotationsAndNonFinite) {
  Rigid3 mirrored;
  mirrored.rotation = Eigen::Vector3d(1, 1, -1).asDiagonal();
  try {
    mirrored.Check();
    FAIL() << "a reflection passed";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("left-handed"), std::string::npos) << e.what();
  }
  Rigid3 scaled;
  scaled.rotation *= 1.001;
  EXPECT_THROW(scaled.Check(), std::invalid_argument);
  Rigid3 nan_translation;
  nan_translation.translation.x() = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(nan_translation.Check(), std::invalid_argument);
  Eigen::Matrix4d not_rigid = Eigen::Matrix4d::Identity();
  not_rigid(3, 2) = -1.0;
  EXPECT_THROW(Rigid3FromMatrix(not_rigid), std::invalid_argument);
}

}  // namespace
}  // namespace camproj
