// The cost of one SQPnP pose, ours (lib/src/fit/sqpnp.h) against OpenCV's
// cv::solvePnP(SOLVEPNP_SQPNP) as closed_form.cc called it: run under callgrind by
// scripts/bench_sqpnp_cost.sh, which subtracts the count of `--solver none` (scenes, warm-up and
// exit alone) and divides by the scenes. The scenes are the stage-cost bench's (camproj's default
// path, docs/bench/stage_cost.md): SynthesizeScene clouds (or planes), 1920 x 1080, fovy 45 deg,
// 0.5 px noise, seeds 1..S, in normalized image coordinates through the true intrinsics.
//
//   sqpnp_cost --solver ours|opencv|none [--n N] [--scenes S] [--plane]
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>

#include "camproj/intrinsics.h"
#include "camproj/synth.h"
#include "fit/sqpnp.h"

namespace {

struct Problem {
  std::vector<Eigen::Vector3d> points;
  std::vector<Eigen::Vector2d> normalized;
  std::vector<cv::Point3d> cv_points;
  std::vector<cv::Point2d> cv_normalized;
};

Problem MakeProblem(uint64_t seed, int n, bool plane) {
  camproj::SynthOptions synth;
  synth.seed = seed;
  synth.num_points = n;
  synth.object = plane ? camproj::SynthObject::kPlane : camproj::SynthObject::kCloud;
  synth.image_size = camproj::ImageSize{1920, 1080};
  synth.fovy_deg = 45.0;
  synth.noise_px = 0.5;
  const camproj::SynthScene scene = camproj::SynthesizeScene(synth);
  Problem problem;
  problem.points = scene.correspondences.points_in_world;
  for (size_t i = 0; i < problem.points.size(); ++i) {
    const Eigen::Vector3d ray =
        camproj::CamRayFromPixel(scene.truth.intrinsics, scene.correspondences.pixels[i]);
    problem.normalized.emplace_back(ray.x() / ray.z(), ray.y() / ray.z());
    problem.cv_points.emplace_back(problem.points[i].x(), problem.points[i].y(),
                                   problem.points[i].z());
    problem.cv_normalized.emplace_back(problem.normalized.back().x(),
                                       problem.normalized.back().y());
  }
  return problem;
}

double Ours(const Problem& problem) {
  Eigen::Matrix3d rotation;
  Eigen::Vector3d translation;
  if (!camproj::internal::SolveSqPnp(problem.points, problem.normalized, &rotation,
                                     &translation)) {
    return 0.0;
  }
  return rotation(0, 0) + translation(0);
}

// closed_form.cc's former call, with its Rodrigues conversion back to a matrix.
double OpenCv(const Problem& problem) {
  cv::Mat rvec;
  cv::Mat tvec;
  if (!cv::solvePnP(problem.cv_points, problem.cv_normalized, cv::Mat::eye(3, 3, CV_64F),
                    cv::Mat(), rvec, tvec, false, cv::SOLVEPNP_SQPNP)) {
    return 0.0;
  }
  cv::Mat r;
  cv::Rodrigues(rvec, r);
  return r.at<double>(0, 0) + tvec.at<double>(0);
}

}  // namespace

int main(int argc, char** argv) {
  std::string solver;
  int n = 6;
  int scenes = 40;
  bool plane = false;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--solver" && i + 1 < argc) {
      solver = argv[++i];
    } else if (arg == "--n" && i + 1 < argc) {
      n = std::atoi(argv[++i]);
    } else if (arg == "--scenes" && i + 1 < argc) {
      scenes = std::atoi(argv[++i]);
    } else if (arg == "--plane") {
      plane = true;
    } else {
      std::fprintf(stderr, "usage: sqpnp_cost --solver ours|opencv|none [--n N] [--scenes S] "
                           "[--plane]\n");
      return 2;
    }
  }
  if ((solver != "ours" && solver != "opencv" && solver != "none") || n < 3 || scenes < 1) {
    std::fprintf(stderr, "sqpnp_cost: --solver ours|opencv|none, --n >= 3, --scenes >= 1\n");
    return 2;
  }
  std::vector<Problem> problems;
  for (int s = 1; s <= scenes; ++s) problems.push_back(MakeProblem(s, n, plane));
  // Both solvers once in every mode, so one-time initialization (OpenCV's) is in the baseline.
  double sum = Ours(problems[0]) + OpenCv(problems[0]);
  for (const Problem& problem : problems) {
    if (solver == "ours") sum += Ours(problem);
    if (solver == "opencv") sum += OpenCv(problem);
  }
  std::printf("%s, %d scenes of %d%s points: checksum %.17g\n", solver.c_str(), scenes, n,
              plane ? " planar" : "", sum);
  return 0;
}
