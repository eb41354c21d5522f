// Fits a camera with the installed library (this links Ceres and OpenCV through camproj::camproj's
// dependencies) and prints its GL projection's first entry: 2 fx / W.
#include <cstdio>
#include <vector>

#include "camproj/camera.h"
#include "camproj/gl.h"
#include "camproj/model_select.h"

int main() {
  camproj::Camera truth;
  truth.image_size = {640, 480};
  truth.intrinsics.fx = truth.intrinsics.fy = 500.0;
  truth.intrinsics.cx = 319.5;
  truth.intrinsics.cy = 239.5;
  truth.cam_from_world.translation = {0.0, 0.0, 5.0};
  std::vector<Eigen::Vector3d> points;
  std::vector<Eigen::Vector2d> pixels;
  for (int i = 0; i < 12; ++i) {
    const Eigen::Vector3d p(i % 3 - 1.0, (i / 3) % 2 - 0.5, i % 4 * 0.5 - 0.7);
    points.push_back(p);
    pixels.push_back(*camproj::PixelFromWorld(truth, p));
  }
  const camproj::FitResult fit = camproj::FitCameraAuto(points, pixels, truth.image_size);
  const Eigen::Matrix4d projection =
      camproj::ClipFromGlEye(fit.camera.intrinsics, fit.camera.image_size, 0.1, 100.0);
  std::printf("fx %.6f, projection(0,0) %.9f\n", fit.camera.intrinsics.fx, projection(0, 0));
  return 0;
}
