#include "camproj/look_at.h"

#include <limits>
#include <random>
#include <stdexcept>

#include <glm/gtc/matrix_transform.hpp>
#include <gtest/gtest.h>

#include "camproj/gl.h"
#include "glm_compare.h"
#include "seeds.h"
#include "test_scenes.h"

namespace camproj {
namespace {

using testing::kExactRelative;

LookAt RandomLookAt(std::mt19937_64& rng) {
  LookAt look_at;
  for (int i = 0; i < 3; ++i) {
    look_at.eye[i] = testing::Uniform(rng, -10, 10);
    look_at.target[i] = testing::Uniform(rng, -10, 10);
    look_at.up[i] = testing::Uniform(rng, -1, 1);
  }
  return look_at;
}

TEST(LookAtTest, HandComputedCameraAtZLookingAtOrigin) {
  // gluLookAt(0,0,5, 0,0,0, 0,1,0): the view matrix is a translation by -5 along z; the CV camera
  // looks along -z of the world with y down, so its rotation is diag(1, -1, -1).
  const Rigid3 cam_from_world =
      CamFromWorldFromLookAt({Eigen::Vector3d(0, 0, 5), Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitY()});
  EXPECT_EQ(cam_from_world.rotation, Eigen::Vector3d(1, -1, -1).asDiagonal().toDenseMatrix());
  EXPECT_EQ(cam_from_world.translation, Eigen::Vector3d(0, 0, 5));
  Eigen::Matrix4d view = Eigen::Matrix4d::Identity();
  view(2, 3) = -5;
  EXPECT_EQ(GlEyeFromWorld(cam_from_world), view);
}

TEST(LookAtTest, ViewMatrixEqualsGlmLookAt) {
  std::mt19937_64 rng(testing::Seed(3));
  for (int i = 0; i < 1000; ++i) {
    const LookAt look_at = RandomLookAt(rng);
    const Eigen::Matrix4d expected = testing::FromGlm(glm::lookAtRH(
        testing::ToGlm(look_at.eye), testing::ToGlm(look_at.target), testing::ToGlm(look_at.up)));
    const Eigen::Matrix4d view = GlEyeFromWorld(CamFromWorldFromLookAt(look_at));
    EXPECT_LT(testing::RelativeDifference(view, expected), kExactRelative) << "case " << i;
  }
}

TEST(LookAtTest, PoseToLookAtAndBackIsExact) {
  std::mt19937_64 rng(testing::Seed(5));
  for (int i = 0; i < 1000; ++i) {
    // The centre is drawn before the rotation (testing::DrawVector3 says why).
    const Eigen::Vector3d center = testing::UniformVector3(rng, -10, 10);
    const Rigid3 cam_from_world = CamFromWorldFromCenter(testing::RandomRotation(rng), center);
    const double distance = testing::LogUniform(rng, 1e-3, 1e3);
    const LookAt look_at = LookAtFromCamFromWorld(cam_from_world, distance);
    EXPECT_NEAR((look_at.target - look_at.eye).norm(), distance, kExactRelative * (distance + 10));
    EXPECT_NEAR(look_at.up.norm(), 1.0, kExactRelative);
    EXPECT_NEAR(look_at.up.dot(look_at.target - look_at.eye), 0.0, kExactRelative * (distance + 10));
    const Rigid3 back = CamFromWorldFromLookAt(look_at);
    // The target's rounding (|eye| ~ 10 against |gaze| ~ distance) limits the gaze direction.
    const double tolerance = kExactRelative * (1.0 + 10.0 / distance);
    EXPECT_LT((back.rotation - cam_from_world.rotation).cwiseAbs().maxCoeff(), tolerance);
    EXPECT_LT((back.translation - cam_from_world.translation).norm(), tolerance * 20);
    // The camera's up is -y of cam: it projects upwards in the image.
    EXPECT_LT((cam_from_world.rotation * look_at.up - Eigen::Vector3d(0, -1, 0)).norm(),
              kExactRelative);
  }
}

TEST(LookAtTest, DegenerateInputIsAClearErrorNotNaN) {
  const Eigen::Vector3d eye(1, 2, 3);
  auto expect_error = [](const LookAt& look_at, const std::string& words) {
    try {
      CamFromWorldFromLookAt(look_at);
      ADD_FAILURE() << "no exception for " << words;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
    }
  };
  expect_error({eye, eye, Eigen::Vector3d::UnitY()}, "equals target");
  expect_error({eye, eye + Eigen::Vector3d(0, 3, 0), Eigen::Vector3d(0, 2, 0)}, "parallel");
  expect_error({eye, eye + Eigen::Vector3d(0, 3, 0), Eigen::Vector3d(0, -2, 0)}, "parallel");
  expect_error({eye, eye + Eigen::Vector3d(0, 0, 1), Eigen::Vector3d::Zero()}, "zero");
  const double nan = std::numeric_limits<double>::quiet_NaN();
  expect_error({Eigen::Vector3d(nan, 0, 0), Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitY()},
               "finite");
  expect_error({eye, Eigen::Vector3d::Zero(), Eigen::Vector3d(0, std::numeric_limits<double>::infinity(), 0)},
               "finite");
  // glm, for contrast, returns NaN for up parallel to the gaze (glm issue #881).
  const glm::dmat4 glm_view =
      glm::lookAtRH(glm::dvec3(1, 2, 3), glm::dvec3(1, 5, 3), glm::dvec3(0, 1, 0));
  EXPECT_TRUE(std::isnan(glm_view[0][0]));
  EXPECT_THROW(LookAtFromCamFromWorld(Rigid3{}, 0.0), std::invalid_argument);
}

TEST(LookAtTest, ExtremeScalesGiveTheSamePose) {
  // A gaze of 1e-200 (no underflow to "eye equals target") or 1e200 (no overflow to NaN).
  const LookAt unit{Eigen::Vector3d::Zero(), Eigen::Vector3d(1, 2, -3), Eigen::Vector3d(0, 1, 0)};
  const Rigid3 expected = CamFromWorldFromLookAt(unit);
  for (const double scale : {1e-200, 1e200}) {
    const LookAt scaled{Eigen::Vector3d::Zero(), scale * unit.target, scale * unit.up};
    const Rigid3 pose = CamFromWorldFromLookAt(scaled);
    EXPECT_LT((pose.rotation - expected.rotation).cwiseAbs().maxCoeff(), kExactRelative);
  }
}

TEST(LookAtTest, ALookAtBeyondADoubleIsRefusedNotInfinite) {
  // A finite pose whose target, eye + distance * gaze, overflows.
  Rigid3 cam_from_world;
  cam_from_world.translation = Eigen::Vector3d(0, 0, -1.5e308);  // eye (0, 0, 1.5e308)
  try {
    LookAtFromCamFromWorld(cam_from_world, 1e308);
    ADD_FAILURE() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("look-at target"), std::string::npos) << e.what();
  }
  EXPECT_NO_THROW(LookAtFromCamFromWorld(cam_from_world, 1.0));
}

}  // namespace
}  // namespace camproj
